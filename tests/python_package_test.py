#!/usr/bin/env python3
"""The leaflux Python package (python/) as a user installs it, against a real leafluxd.

Run as a script, it copies python/ and proto/ to a temporary folder (no generated module),
installs the package there with pip into a virtual environment of the system's packages
(`pip install --no-build-isolation --no-index`: no network, Debian's setuptools, zmq and
protobuf), then runs this file's tests with that environment's Python: under pytest when
it is installed (Debian python3-pytest), with a plain runner otherwise.

The tests: the package is the installed one, its protoc-generated modules import; a
LocalDaemon lights a small scene over cycles (finite light, the sun's irradiance on an
unshaded leaf, absorbed power within what reaches it, the energy balance); PAR in photons
from the daemon (4.57 times the W figures; None, and empty CSV cells, for NIR); CSV round
trip; a pandas DataFrame (skipped without pandas) and a clear error without it; a request
to no daemon raises RequestTimeout naming the endpoint within its timeout; a stale reply
(of another request id) is dropped; errors are typed with code and field; a cycle given
resync= survives the daemon's SIGKILL and restart.

Usage: python_package_test.py [BUILD_DIR]   (or $LEAFLUX_BUILD; leafluxd in BUILD_DIR/server)
       pytest tests/python_package_test.py  (the checkout's python/, not installed)
"""
from __future__ import annotations

import csv
import math
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
INSTALLED = os.environ.get("LEAFLUX_TEST_INSTALLED")  # the environment's prefix
if not INSTALLED and __name__ != "__main__":
    sys.path.insert(0, os.path.join(ROOT, "python"))  # pytest on the checkout

try:
    import pytest
except ImportError:  # the plain runner below
    pytest = None


class Skipped(Exception):
    pass


def skip(reason):
    if pytest:
        pytest.skip(reason)
    raise Skipped(reason)


def build_dir():
    return os.environ.get("LEAFLUX_BUILD") or os.path.join(ROOT, "build", "release")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def scene(leaves=3):
    """One band, a grey ground, a vertical sun of 400 W/m², `leaves` square leaves of
    1 dm² stacked 20 cm apart, offset so that each shades part of the one below."""
    from leaflux import pb
    s = pb.Scene(version=pb.PROTOCOL_VERSION_CURRENT)
    s.bands.add(name="PAR", wavelength_min_nm=400, wavelength_max_nm=700)
    s.optics.add(id="leaf").bands["PAR"].CopyFrom(
        pb.BandOptics(rho_upper=0.1, rho_lower=0.1, tau_upper=0.05, tau_lower=0.05))
    s.optics.add(id="ground").bands["PAR"].CopyFrom(pb.BandOptics(rho_upper=0.2))
    ground = s.environment.add(name="ground", optics="ground")
    ground.mesh.positions.extend([-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, 2, 0])
    ground.mesh.triangles.extend([0, 1, 2, 0, 2, 3])
    sun = s.suns.add()
    sun.direction.z = 1
    sun.normal_irradiance["PAR"] = 400
    s.nodes.add(id=1, type=pb.NODE_TYPE_PLANT, name="plant")
    s.nodes.extend(leaf(i) for i in range(leaves))
    return s


def leaf(index):
    from leaflux import frame, pb
    node = pb.Node(id=10 + index, parent=1, type=pb.NODE_TYPE_LEAF, name=f"leaf{index}")
    node.frame.CopyFrom(frame([[1, 0, 0, 0.05 * index], [0, 1, 0, 0], [0, 0, 1, 1.0 - 0.2 * index]]))
    node.organ.optics = "leaf"
    node.organ.mesh.positions.extend([0, 0, 0, 0.1, 0, 0, 0.1, 0.1, 0, 0, 0.1, 0])
    node.organ.mesh.triangles.extend([0, 1, 2, 0, 2, 3])
    return node


def hrc():
    from leaflux import pb
    return pb.SolverSettings(solver=pb.SOLVER_KIND_HRC, epsilon=1e-4, threads=1)


def daemon(**kwargs):
    from leaflux import LocalDaemon
    return LocalDaemon(os.path.join(build_dir(), "server", "leafluxd"), solver_threads=1,
                       **kwargs)


def lit_cycles(cycles=3):
    """Light of `cycles` cycles: a leaf more each cycle, the last one with structures."""
    from leaflux import Client
    lights = []
    with daemon() as d, Client(d.endpoint) as client:
        session = client.open(scene(1), hrc(), "test")
        for number in range(1, cycles + 1):
            lights.append(client.cycle(session, number, added=[leaf(number)], bands=["PAR"],
                                       structures=number == cycles))
        client.close(session)
    return lights


_lights = []


def light():
    if not _lights:
        _lights.extend(lit_cycles())
    return _lights[-1]


# --- the tests ---

def test_installed_package():
    import leaflux
    from leaflux import leaflux_pb2, policy_pb2
    if INSTALLED:
        assert os.path.realpath(leaflux.__file__).startswith(os.path.realpath(INSTALLED)), \
            f"leaflux imported from {leaflux.__file__}, not from the installation {INSTALLED}"
    assert leaflux.pb is leaflux_pb2
    assert leaflux_pb2.PROTOCOL_VERSION_CURRENT == 1
    policy_pb2.DESCRIPTOR  # generated by protoc, importing leaflux_pb2 within the package
    reply = leaflux_pb2.Reply.FromString(leaflux_pb2.Reply(request_id=7).SerializeToString())
    assert reply.request_id == 7


def test_cycles_light_sensibly():
    from leaflux import CycleLight, OrganLight
    lights = light() and _lights
    assert [c.number for c in lights] == [1, 2, 3]
    for number, cycle in enumerate(lights, 1):
        assert isinstance(cycle, CycleLight)
        leaves = [o for o in cycle.organs if o.node]
        assert sorted(o.node for o in leaves) == list(range(10, 11 + number)), cycle.organs
        assert any(o.name == "ground" and o.node == 0 for o in cycle.organs)
        for organ in cycle.organs:
            assert isinstance(organ, OrganLight)
            b = organ.band("PAR")
            values = [organ.area_m2, b.irradiance_upper_wm2, b.irradiance_lower_wm2, b.absorbed_w]
            assert all(math.isfinite(v) for v in values), organ
            assert b.irradiance_upper_wm2 >= 0 and b.irradiance_lower_wm2 >= 0 and b.absorbed_w >= 0
            # Absorbed: at most what reaches both sides (1 - ρ - τ of it for leaves).
            reaching = (b.irradiance_upper_wm2 + b.irradiance_lower_wm2) * organ.area_m2
            assert b.absorbed_w <= reaching * (1 + 1e-6), organ
            if organ.node:
                assert abs(organ.area_m2 - 0.01) < 1e-9
                assert b.light_vector is not None and all(map(math.isfinite, b.light_vector))
                assert b.stderr_upper_wm2 == -1  # HRC gives no estimate
        # The top leaf, unshaded under a vertical sun of 400 W/m², gets it on its upper side.
        top = cycle.organ(10).band("PAR")
        assert abs(top.irradiance_upper_wm2 - 400) < 4, top
        assert 0.8 * 400 * 0.01 * 0.85 < top.absorbed_w < 1.2 * 400 * 0.01 * 0.85, top
        # Lower leaves are shaded in part.
        assert cycle.organ(10 + number).band("PAR").irradiance_upper_wm2 < 400
        for balance in cycle.statistics.balance:
            assert balance.incident_w > 0
            assert abs(balance.absorbed_w + balance.escaped_w - balance.incident_w) \
                < 0.01 * balance.incident_w, balance
    last = lights[-1]
    plants = [s for s in last.structures if s.type == "NODE_TYPE_PLANT"]
    assert len(plants) == 1 and plants[0].organs == 4, last.structures
    assert abs(plants[0].band("PAR").absorbed_w - last.absorbed_w("PAR")) < 1e-9 * (1 + last.absorbed_w("PAR"))


def test_csv_round_trip():
    from leaflux import CSV_COLUMNS, CycleLight
    cycle = light()
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cycle.csv")
        cycle.to_csv(path)
        with open(path) as f:
            header = f.readline().strip().split(",")
            rows = f.readlines()
        assert header == CSV_COLUMNS
        assert len(rows) == len(cycle.organs) + len(cycle.structures)  # one band
        back = CycleLight.read_csv(path, session=cycle.session)
    assert back.number == cycle.number
    assert back.organs == cycle.organs  # every float exactly
    assert back.structures == cycle.structures


def test_photon_units():
    from leaflux import DAYLIGHT_PAR_UMOL_PER_J, pb, photon_umol_per_j
    assert DAYLIGHT_PAR_UMOL_PER_J == 4.57
    assert photon_umol_per_j(pb.Band(name="PAR")) == 4.57
    assert photon_umol_per_j(pb.Band(name="visible", wavelength_min_nm=400,
                                     wavelength_max_nm=700)) == 4.57
    assert photon_umol_per_j(pb.Band(name="red", photon_umol_per_j=5.52)) == 5.52
    assert photon_umol_per_j(pb.Band(name="NIR", wavelength_min_nm=700,
                                     wavelength_max_nm=2500)) is None
    # The top leaf under the 400 W/m² sun: 1,828 µmol m⁻² s⁻¹.
    top = light().organ(10).band("PAR")
    assert abs(top.irradiance_upper_wm2 * photon_umol_per_j(pb.Band(name="PAR")) - 1828) < 20


def test_photon_light_from_the_daemon():
    from leaflux import Client, CycleLight, pb
    s = scene(2)
    s.bands.add(name="NIR", wavelength_min_nm=700, wavelength_max_nm=2500)  # no photon unit
    for optics in s.optics:
        optics.bands["NIR"].CopyFrom(optics.bands["PAR"])
    s.suns[0].normal_irradiance["NIR"] = 300
    with daemon() as d, Client(d.endpoint) as client:
        session = client.open(s, hrc())
        cycle = client.cycle(session, 1, structures=True)
    items = [*cycle.organs, *cycle.structures]
    assert items and all(len(i.bands) == 2 for i in items), items
    for item in items:
        par, nir = item.band("PAR"), item.band("NIR")
        for photons, watts in ((par.photon_irradiance_upper_umol_m2_s, par.irradiance_upper_wm2),
                               (par.photon_irradiance_lower_umol_m2_s, par.irradiance_lower_wm2),
                               (par.absorbed_umol_s, par.absorbed_w)):
            assert photons is not None and abs(photons - 4.57 * watts) <= 1e-9 * (1 + photons), \
                (item, photons, watts)
        assert (nir.photon_irradiance_upper_umol_m2_s, nir.photon_irradiance_lower_umol_m2_s,
                nir.absorbed_umol_s) == (None, None, None), item
    assert cycle.organ(10).band("PAR").photon_irradiance_upper_umol_m2_s > 1800  # 400 W/m²
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cycle.csv")
        cycle.to_csv(path)
        with open(path) as f:
            rows = list(csv.DictReader(f))
        back = CycleLight.read_csv(path)
    for row in rows:
        filled = row["band"] == "PAR"
        for column in ("photon_irradiance_upper_umol_m2_s", "photon_irradiance_lower_umol_m2_s",
                       "absorbed_umol_s"):
            assert bool(row[column]) == filled, row  # an empty cell for NIR
    assert back.organs == cycle.organs and back.structures == cycle.structures
    try:
        import pandas  # noqa: F401
    except ImportError:
        return
    frame = cycle.to_dataframe()
    par = frame[frame.band == "PAR"]
    assert ((par.absorbed_umol_s - 4.57 * par.absorbed_w).abs() < 1e-9 * (1 + par.absorbed_umol_s)).all()
    assert frame[frame.band == "NIR"].absorbed_umol_s.isna().all()


def test_dataframe():
    try:
        import pandas  # noqa: F401
    except ImportError:
        skip("pandas is not installed (Debian python3-pandas)")
    cycle = light()
    frame = cycle.to_dataframe()
    assert list(frame.columns) == __import__("leaflux").CSV_COLUMNS
    assert len(frame) == len(cycle.organs) + len(cycle.structures)
    organs = frame[(frame.kind == "organ") & (frame.node > 0)]
    assert abs(organs.absorbed_w.sum() - cycle.absorbed_w("PAR")) < 1e-9


def test_dataframe_without_pandas_says_so():
    from leaflux import CycleLight
    saved = sys.modules.get("pandas")
    sys.modules["pandas"] = None  # import pandas now raises ImportError
    try:
        CycleLight("s", 1).to_dataframe()
        raise AssertionError("to_dataframe without pandas did not raise")
    except ImportError as e:
        assert "pandas" in str(e) and "python3-pandas" in str(e), e
    finally:
        if saved is None:
            del sys.modules["pandas"]
        else:
            sys.modules["pandas"] = saved


def test_timeout_names_the_endpoint():
    from leaflux import Client, LeafluxError, RequestTimeout
    endpoint = f"tcp://127.0.0.1:{free_port()}"  # nobody there
    with Client(endpoint, timeout_s=0.5) as client:
        started = time.monotonic()
        try:
            client.status()
            raise AssertionError("a status with no daemon was answered")
        except RequestTimeout as e:
            elapsed = time.monotonic() - started
            assert isinstance(e, TimeoutError) and isinstance(e, LeafluxError)
            assert endpoint in str(e) and e.endpoint == endpoint, e
            assert e.code == "ERROR_CODE_IO" and e.field == "status" and e.timeout_s == 0.5
            assert 0.45 < elapsed < 1.5, elapsed


def test_timeouts_per_kind():
    from leaflux import Client, Timeouts, pb
    with Client("tcp://127.0.0.1:1") as client:
        assert client.timeouts == Timeouts(30.0, 60.0, 0.010)
        request = pb.Request()
        request.status.SetInParent()
        assert client.timeout_s(request) == 30.0
        request = pb.Request()
        request.open_session.scene.CopyFrom(scene(3))
        assert abs(client.timeout_s(request) - 60.03) < 1e-9
    with Client("tcp://127.0.0.1:1", timeout_s=2) as client:
        assert client.timeouts == Timeouts.all(2)


def fake_daemon(answer):
    """A ROUTER on a free port answering each request with answer(request): a list of
    replies to send, in order. Returns (endpoint, stop)."""
    import zmq
    from leaflux import pb
    context = zmq.Context.instance()
    router = context.socket(zmq.ROUTER)
    router.setsockopt(zmq.LINGER, 0)
    port = router.bind_to_random_port("tcp://127.0.0.1")
    done = threading.Event()

    def serve():
        while not done.is_set():
            if router.poll(50):
                frames = router.recv_multipart()
                request = pb.Request.FromString(frames[-1])
                for reply in answer(request):
                    router.send_multipart([*frames[:-1], reply.SerializeToString()])
        router.close()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()

    def stop():
        done.set()
        thread.join()
    return f"tcp://127.0.0.1:{port}", stop


def test_stale_reply_dropped():
    from leaflux import Client, InvalidArgument, pb

    def answer(request):
        stale = pb.Reply(version=1, request_id=request.request_id + 1000)
        stale.status.session_count = 99  # the answer to some other request
        right = pb.Reply(version=1, request_id=request.request_id)
        right.status.session_count = 1
        return [stale, right]

    endpoint, stop = fake_daemon(answer)
    try:
        with Client(endpoint, timeout_s=5) as client:
            assert client.status().session_count == 1
            assert client.status().session_count == 1  # the second's stale one dropped too
    finally:
        stop()

    def undecodable(request):  # id 0 with an error: the daemon could not read the request
        reply = pb.Reply(version=1, request_id=0)
        reply.error.code, reply.error.field = pb.ERROR_CODE_INVALID_ARGUMENT, "version"
        reply.error.message = "no"
        return [reply]

    endpoint, stop = fake_daemon(undecodable)
    try:
        with Client(endpoint, timeout_s=5) as client:
            try:
                client.status()
                raise AssertionError("an error of request id 0 was not taken")
            except InvalidArgument as e:
                assert e.field == "version" and e.endpoint == endpoint
    finally:
        stop()


def test_late_reply_after_timeout_never_read():
    from leaflux import Client, RequestTimeout, pb
    held = []

    def answer(request):  # the first request is answered only with the second's reply
        reply = pb.Reply(version=1, request_id=request.request_id)
        reply.status.session_count = request.request_id
        held.append(reply)
        return [] if len(held) == 1 else held

    endpoint, stop = fake_daemon(answer)
    try:
        with Client(endpoint, timeout_s=0.3) as client:
            try:
                client.status()
                raise AssertionError("answered")
            except RequestTimeout:
                pass
            assert client.status().session_count == 2
    finally:
        stop()


def test_typed_errors():
    from leaflux import Client, DaemonError, InvalidArgument, UnknownSession
    with daemon() as d, Client(d.endpoint, timeout_s=30) as client:
        try:
            client.cycle("0" * 32, 1)
            raise AssertionError("a cycle of an unknown session was answered")
        except UnknownSession as e:
            assert isinstance(e, DaemonError)
            assert e.code == "ERROR_CODE_UNKNOWN_SESSION" and e.endpoint == d.endpoint
        session = client.open(scene(1), hrc())
        client.cycle(session, 1)
        try:
            client.cycle(session, 1)
            raise AssertionError("a cycle sent twice was applied")
        except InvalidArgument as e:
            assert e.field == "number" and e.code_value == 1, e
        assert client.status(session).sessions[0].cycles == 1


def test_render_draws_the_last_cycles_light():
    """The daemon's picture of a session: the top leaf, seen from above on the linear grey
    scale, has the grey of the irradiance the cycle returned; bad settings are refused."""
    import io
    import matplotlib.image
    from leaflux import Client, NotFound
    with daemon() as d, Client(d.endpoint, timeout_s=30) as client:
        session = client.open(scene(1), hrc())
        light = client.cycle(session, 1)
        irradiance = light.organ(10).band("PAR").irradiance_upper_wm2
        picture = client.render(session, eye=(0.05, 0.05, 3), look=(0.05, 0.05, 1), up=(0, 1, 0),
                                fov_deg=2, size=(64, 48), palette="grey", value_range=(0, 800))
        assert picture.caption == "PAR irradiance, side facing the camera (W/m²)", picture.caption
        image = matplotlib.image.imread(io.BytesIO(picture.png), format="png")
        assert image.shape[1] == 64 and image.shape[0] > 48, image.shape
        assert abs(image[24, 32, 0] * 255 - round(255 * irradiance / 800)) < 0.5, image[24, 32]
        for bad in ({"quantity": "heat"}, {"side": "left"}):
            try:
                client.render(session, eye=(0, 0, 3), look=(0, 0, 1), **bad)
                raise AssertionError(f"{bad} was drawn")
            except ValueError as e:
                assert next(iter(bad)) in str(e), e
        for bad, field in (({"band": "NIR"}, "render.band"), ({"quantity": "colour"}, "render.rgb[0]")):
            try:
                client.render(session, eye=(0, 0, 3), look=(0, 0, 1), **bad)
                raise AssertionError(f"{bad}: a band the scene lacks was drawn")
            except NotFound as e:
                assert e.field == field, e


def test_resync_after_a_restart():
    from leaflux import Client, LocalDaemon, pb
    port = free_port()
    moved = leaf(1)
    moved.frame.m[11] = 0.7

    def as_before():
        return scene(2), hrc()

    light_of = {}
    for restart in (False, True):
        d = daemon(port=port)
        try:
            with Client(d.endpoint, status_timeout_s=10, scene_timeout_s=5) as client:
                session = client.open(scene(2), hrc())
                client.cycle(session, 1, resync=as_before)
                if restart:
                    os.kill(d.pid, signal.SIGKILL)
                    d.stop()
                    d = daemon(port=port)
                result = client.cycle(session, 2, updated=[moved], resync=as_before)
                light_of[restart] = [(o.node, o.bands) for o in result.organs]
        finally:
            d.stop()
    assert light_of[True] == light_of[False]
    assert isinstance(LocalDaemon, type) and pb.PROTOCOL_VERSION_CURRENT == 1


def test_curve():
    import zmq
    from leaflux import Client, RequestTimeout
    if not zmq.has("curve"):
        skip("this libzmq has no CurveZMQ")
    public, secret = zmq.curve_keypair()
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "server.secret")
        with open(os.open(path, os.O_WRONLY | os.O_CREAT, 0o600), "w") as f:
            f.write(secret.decode() + "\n")
        with open(os.path.join(tmp, "server.public"), "w") as f:
            f.write(public.decode() + "\n")
        with daemon(curve_secret_key=path) as d:
            assert d.curve_server_key == public.decode()
            for key in (d.curve_server_key, os.path.join(tmp, "server.public")):
                with Client(d.endpoint, timeout_s=5, curve_server_key=key) as client:
                    assert client.status().session_count == 0
            with Client(d.endpoint, timeout_s=0.3) as plain:  # no key: never answered
                try:
                    plain.status()
                    raise AssertionError("a connection without CurveZMQ was answered")
                except RequestTimeout:
                    pass


def test_local_daemon_errors():
    from leaflux import DaemonStartError, LocalDaemon
    missing = os.path.join(tempfile.gettempdir(), "no-such-dir", "leafluxd")
    try:
        LocalDaemon(missing)
        raise AssertionError("a LocalDaemon of a missing leafluxd started")
    except DaemonStartError as e:
        assert missing in str(e), e
    with socket.socket() as busy:  # a port in use: leafluxd's own sentence
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        try:
            daemon(port=port)
            raise AssertionError(f"a LocalDaemon on the busy port {port} started")
        except DaemonStartError as e:
            assert f"tcp://127.0.0.1:{port}" in str(e) and "in use" in str(e), e


TESTS = [v for k, v in list(globals().items()) if k.startswith("test_")]


def run_plain():
    failed = 0
    for test in TESTS:
        try:
            test()
            print(f"ok      {test.__name__}")
        except Skipped as e:
            print(f"skipped {test.__name__}: {e}")
        except Exception as e:  # noqa: BLE001
            import traceback
            traceback.print_exc()
            print(f"FAILED  {test.__name__}: {e}")
            failed += 1
    return 1 if failed else 0


def install_and_run():
    """Installs the package into a fresh environment and runs the tests there."""
    if len(sys.argv) > 1:
        os.environ["LEAFLUX_BUILD"] = os.path.abspath(sys.argv[1])
    with tempfile.TemporaryDirectory(prefix="leaflux_package_test_") as tmp:
        source = os.path.join(tmp, "checkout")
        ignore = shutil.ignore_patterns("*_pb2.py", "build", "*.egg-info", "__pycache__")
        shutil.copytree(os.path.join(ROOT, "python"), os.path.join(source, "python"), ignore=ignore)
        shutil.copytree(os.path.join(ROOT, "proto"), os.path.join(source, "proto"), ignore=ignore)
        env = os.path.join(tmp, "venv")
        python = os.path.join(env, "bin", "python")
        made = subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", env],
                              capture_output=True, text=True)
        if os.environ.get("LEAFLUX_TEST_TARGET"):  # to test the fallback
            made.returncode, made.stderr = 1, "LEAFLUX_TEST_TARGET is set"
        if made.returncode == 0:
            install = [python, "-m", "pip", "install"]
            prefix = env
            run_env = dict(os.environ)
        else:  # no venv module (Debian python3-venv): a --target folder instead
            print(f"no venv ({made.stderr.strip()[-200:]}): installing with pip --target")
            prefix = os.path.join(tmp, "target")
            install = [sys.executable, "-m", "pip", "install", "--no-deps", "--target", prefix]
            python = sys.executable
            run_env = dict(os.environ, PYTHONPATH=prefix)
        command = [*install, "--no-build-isolation", "--no-index", "--quiet",
                   os.path.join(source, "python")]
        print("$", " ".join(command), flush=True)
        installed = subprocess.run(command, cwd=tmp)
        if installed.returncode != 0:
            print("FAIL: pip install of the package failed")
            return 1
        run_env["LEAFLUX_TEST_INSTALLED"] = prefix
        has_pytest = subprocess.run([python, "-c", "import pytest"], env=run_env,
                                    capture_output=True).returncode == 0
        test = ([python, "-m", "pytest", "-q", "-p", "no:cacheprovider", os.path.abspath(__file__)]
                if has_pytest else [python, os.path.abspath(__file__), "--plain"])
        print("$", " ".join(test), flush=True)
        return subprocess.run(test, cwd=tmp, env=run_env).returncode


if __name__ == "__main__":
    if "--plain" in sys.argv:
        if not INSTALLED:
            sys.path.insert(0, os.path.join(ROOT, "python"))
        sys.exit(run_plain())
    sys.exit(install_and_run())
