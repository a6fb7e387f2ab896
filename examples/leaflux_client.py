"""A Python client of leafluxd, for scripted growth experiments.

Needs Debian's python3-zmq and python3-protobuf, and the `leaflux_pb2` module the build
generates (build/release/proto, or $LEAFLUX_BUILD/proto): examples find it by themselves.

    from leaflux_client import Client, pb
    with Client("tcp://127.0.0.1:5555") as client:
        session = client.open(scene, pb.SolverSettings(solver=pb.SOLVER_KIND_HRC, epsilon=1e-4))
        result = client.cycle(session, 1, added=[...], bands=["PAR"])
        for organ in result.organs: ...
"""
import os
import sys

# The build whose modules and programs the examples use: LEAFLUX_BUILD, or build/release.
_build = os.environ.get("LEAFLUX_BUILD") or os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", "build", "release")
for _module_dir in (os.path.join(_build, "proto"), os.path.join(_build, "growth_stub")):
    if os.path.isdir(_module_dir) and _module_dir not in sys.path:
        sys.path.append(_module_dir)

import zmq  # noqa: E402

import leaflux_pb2 as pb  # noqa: E402


class LeafluxError(Exception):
    """The daemon answered with an Error: `code`, `field` and `node` tell what and where."""

    def __init__(self, error):
        self.code = pb.ErrorCode.Name(error.code)
        self.field = error.field
        self.node = error.node
        where = f" ({error.field})" if error.field else ""
        super().__init__(f"{self.code}{where}: {error.message}")


class Client:
    def __init__(self, endpoint="tcp://127.0.0.1:5555", timeout_s=600):
        self._context = zmq.Context.instance()
        self._socket = self._context.socket(zmq.DEALER)
        self._socket.setsockopt(zmq.LINGER, 0)
        self._socket.connect(endpoint)
        self._timeout_ms = int(timeout_s * 1000)
        self._next_id = 1

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._socket.close()

    def call(self, request):
        """Sends a Request, returns its Reply (raises LeafluxError on an Error reply)."""
        request.version = pb.PROTOCOL_VERSION_CURRENT
        request.request_id = self._next_id
        self._next_id += 1
        self._socket.send_multipart([b"", request.SerializeToString()])
        if not self._socket.poll(self._timeout_ms):
            raise TimeoutError(f"no reply from leafluxd within {self._timeout_ms / 1000} s")
        reply = pb.Reply()
        reply.ParseFromString(self._socket.recv_multipart()[-1])
        if reply.HasField("error"):
            raise LeafluxError(reply.error)
        return reply

    def open(self, scene, settings=None, species=""):
        """Opens a session for a pb.Scene (bands, optics, environment, sources, first nodes)."""
        request = pb.Request()
        request.open_session.scene.CopyFrom(scene)
        if settings is not None:
            request.open_session.settings.CopyFrom(settings)
        request.open_session.species = species
        return self.call(request).opened.session

    def cycle(self, session, number, added=(), updated=(), removed=(), suns=None, bands=(),
              leaves=True, structures=False):
        """Sends one cycle's delta; returns the pb.CycleResult."""
        request = pb.Request()
        c = request.cycle
        c.session, c.number = session, number
        c.delta.added.extend(added)
        c.delta.updated.extend(updated)
        c.delta.removed.extend(removed)
        if suns is not None:
            c.suns.extend(suns)
        c.outputs.leaves, c.outputs.structures = leaves, structures
        c.outputs.bands.extend(bands)
        return self.call(request).cycle

    def status(self, session=""):
        request = pb.Request()
        request.status.session = session
        return self.call(request).status

    def close(self, session):
        request = pb.Request()
        request.close_session.session = session
        self.call(request)

    def shutdown(self):
        request = pb.Request()
        request.shutdown.SetInParent()
        self.call(request)


def frame(matrix):
    """A pb.Frame from a 3×4 (or 4×4) row-major matrix given as nested lists."""
    f = pb.Frame()
    f.m.extend(v for row in matrix[:3] for v in row)
    return f


def band_light(organ, band):
    """The pb.BandLight of `band` in an OrganLight or StructureLight."""
    return next(b for b in organ.bands if b.band == band)


class LocalDaemon:
    """Starts leafluxd on a loopback port for the duration of a `with` block, then shuts it
    down through the protocol. `endpoint` is where to connect."""

    def __init__(self, leafluxd=os.path.join(_build, "server", "leafluxd"), port=5576):
        import subprocess
        import time
        self.endpoint = f"tcp://127.0.0.1:{port}"
        self._process = subprocess.Popen([leafluxd, "--bind", self.endpoint],
                                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with Client(self.endpoint, timeout_s=0.2) as probe:
            for _ in range(50):
                try:
                    probe.status()
                    return
                except TimeoutError:
                    time.sleep(0.1)
        self._process.kill()
        raise RuntimeError(f"leafluxd did not answer on {self.endpoint}")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        with Client(self.endpoint, timeout_s=10) as client:
            client.shutdown()
        self._process.wait(timeout=30)
