"""A Python client of leafluxd, for scripted growth experiments.

Needs Debian's python3-zmq and python3-protobuf, and the `leaflux_pb2` module the build
generates (build/release/proto, or $LEAFLUX_BUILD/proto): examples find it by themselves.

    from leaflux_client import Client, pb
    with Client("tcp://127.0.0.1:5555") as client:
        session = client.open(scene, pb.SolverSettings(solver=pb.SOLVER_KIND_HRC, epsilon=1e-4))
        result = client.cycle(session, 1, added=[...], bands=["PAR"])
        for organ in result.organs: ...

Every request gets a new request id and only the reply of that id is taken (a late reply to
a request given up on is dropped). A request unanswered in time raises TimeoutError naming
the endpoint, and the connection is made anew. Given `resync` (a function returning the
session's whole scene and settings as they were before this cycle), `cycle` survives a
daemon restart or a lost reply: it reconnects, resyncs the session and sends the cycle once
more.
"""
import os
import sys
import time

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


def _organs(nodes):
    return sum(1 for n in nodes if n.HasField("organ"))


class Client:
    """A connection to leafluxd.

    Timeouts: Status, close and shutdown wait `status_timeout_s`; open, resync and cycle,
    which validate or solve a scene, wait `scene_timeout_s` plus `per_organ_s` for each
    organ of the session's scene (as far as this client sent them). `timeout_s`, when
    given, is the wait of every request.
    """

    def __init__(self, endpoint="tcp://127.0.0.1:5555", timeout_s=None, status_timeout_s=30.0,
                 scene_timeout_s=60.0, per_organ_s=0.01):
        self.endpoint = endpoint
        self._context = zmq.Context.instance()
        self._socket = None
        if timeout_s is not None:
            status_timeout_s = scene_timeout_s = timeout_s
            per_organ_s = 0.0
        self._status_timeout_s, self._scene_timeout_s = status_timeout_s, scene_timeout_s
        self._per_organ_s = per_organ_s
        self._next_id = 1
        self._organs = {}  # by session: organs sent, removals aside
        self._max_message_bytes = None  # the daemon's, once asked (0: not told)
        self.reconnect()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._socket.close()

    def reconnect(self):
        """A new connection to the same endpoint: replies to the old one are never read."""
        self._max_message_bytes = None  # perhaps another daemon now
        if self._socket is not None:
            self._socket.close()
        self._socket = self._context.socket(zmq.DEALER)
        self._socket.setsockopt(zmq.LINGER, 0)
        if "[" in self.endpoint:
            self._socket.setsockopt(zmq.IPV6, 1)
        self._socket.connect(self.endpoint)

    def _timeout_s(self, request):
        kind = request.WhichOneof("body")
        if kind == "open_session":
            organs = _organs(request.open_session.scene.nodes)
        elif kind == "resync":
            organs = _organs(request.resync.scene.nodes)
        elif kind == "cycle":
            organs = (self._organs.get(request.cycle.session, 0)
                      + _organs(request.cycle.delta.added))
        else:
            return self._status_timeout_s
        return self._scene_timeout_s + self._per_organ_s * organs

    def call(self, request):
        """Sends a Request, returns its Reply (raises LeafluxError on an Error reply,
        TimeoutError when none comes in time)."""
        request.version = pb.PROTOCOL_VERSION_CURRENT
        request_id = request.request_id = self._next_id
        self._next_id += 1
        timeout_s = self._timeout_s(request)
        payload = request.SerializeToString()
        # ZeroMQ cuts off, unanswered, a request over twice the daemon's limit: a large one
        # is checked against the limit first (asked once a connection).
        if len(payload) > 1 << 20 and request.WhichOneof("body") != "status":
            if self._max_message_bytes is None:
                self._max_message_bytes = self.status().max_message_bytes
            if 0 < self._max_message_bytes < len(payload):
                error = pb.Error(code=pb.ERROR_CODE_TOO_LARGE, message=(
                    f"the request of {len(payload)} bytes exceeds the limit of leafluxd at "
                    f"{self.endpoint}, {self._max_message_bytes} bytes (--max-message-mb): "
                    "not sent"))
                raise LeafluxError(error)
        self._socket.send_multipart([b"", payload])
        deadline = time.monotonic() + timeout_s
        while True:
            left_ms = max(0, int(1000 * (deadline - time.monotonic())))
            if not self._socket.poll(left_ms):
                self.reconnect()  # a late reply must not answer the next request
                raise TimeoutError(f"no reply from leafluxd at {self.endpoint} within "
                                   f"{timeout_s:g} s (is it running? busy with a long solve?)")
            reply = pb.Reply()
            reply.ParseFromString(self._socket.recv_multipart()[-1])
            # Id 0: the daemon could not read the request's id (it did not decode).
            if reply.request_id == request_id or (reply.request_id == 0
                                                  and reply.HasField("error")):
                break
        if reply.HasField("error"):
            raise LeafluxError(reply.error)
        if request.WhichOneof("body") == "cycle":
            session = request.cycle.session
            self._organs[session] = (self._organs.get(session, 0)
                                     + _organs(request.cycle.delta.added))
        return reply

    def open(self, scene, settings=None, species=""):
        """Opens a session for a pb.Scene (bands, optics, environment, sources, first nodes)."""
        request = pb.Request()
        request.open_session.scene.CopyFrom(scene)
        if settings is not None:
            request.open_session.settings.CopyFrom(settings)
        request.open_session.species = species
        session = self.call(request).opened.session
        self._organs[session] = _organs(scene.nodes)
        return session

    def resync(self, session, scene, settings=None, last_cycle=0):
        """Gives the daemon the session's whole scene under its id (after a restart, or a
        cycle gone unanswered); `last_cycle`: the number of the last cycle it includes."""
        request = pb.Request()
        request.resync.session = session
        request.resync.scene.CopyFrom(scene)
        if settings is not None:
            request.resync.settings.CopyFrom(settings)
        request.resync.last_cycle = last_cycle
        self.call(request)
        self._organs[session] = _organs(scene.nodes)

    def cycle(self, session, number, added=(), updated=(), removed=(), suns=None, bands=(),
              leaves=True, structures=False, resync=None):
        """Sends one cycle's delta; returns the pb.CycleResult.

        `resync`: a function returning (scene, settings), the session as it was before this
        cycle. Given it, a cycle unanswered in time, or whose session the daemon lost (it
        restarted), is sent once more after a new connection and a Resync."""
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
        try:
            return self.call(request).cycle
        except (TimeoutError, LeafluxError) as e:
            lost = isinstance(e, TimeoutError) or e.code == "ERROR_CODE_UNKNOWN_SESSION"
            if resync is None or not lost:
                raise
            print(f"leaflux_client: cycle {number} of session {session}: {e}; reconnecting, "
                  "resyncing and sending it again", file=sys.stderr)
        self.reconnect()
        scene, settings = resync()
        self.resync(session, scene, settings, last_cycle=number - 1)
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
