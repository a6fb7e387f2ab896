"""Client: one connection to leafluxd (a ZeroMQ DEALER socket), as docs/protocol.md says.

Every request gets a new request id and only the reply of that id is taken (a late reply
to a request given up on is dropped). A request unanswered in time raises RequestTimeout
naming the endpoint, and the connection is made anew. Given `resync` (a function returning
the session's whole scene and settings as they were before this cycle), `cycle` survives
a daemon restart or a lost reply: it reconnects, resyncs the session and sends the cycle
once more.
"""
from __future__ import annotations

import logging
import math
import os
import time
from dataclasses import dataclass
from typing import Callable, Dict, Iterable, Optional, Sequence, Tuple

import zmq

from . import leaflux_pb2 as pb
from .errors import LeafluxError, RequestTimeout, TooLarge, from_reply
from .results import CycleLight

log = logging.getLogger("leaflux")

DEFAULT_ENDPOINT = "tcp://127.0.0.1:5555"

ResyncFunction = Callable[[], Tuple["pb.Scene", Optional["pb.SolverSettings"]]]


@dataclass(frozen=True)
class Timeouts:
    """How long a request waits for its reply, as the C++ client's (server/client.h):
    Status, CloseSession and Shutdown wait `status_s`; OpenSession, Resync and Cycle, which
    validate or solve a scene, wait `scene_s` plus `per_organ_s` for each organ of the
    session's scene (as far as this client sent them)."""
    status_s: float = 30.0
    scene_s: float = 60.0
    per_organ_s: float = 0.010

    @classmethod
    def all(cls, seconds: float) -> "Timeouts":
        """Every request waits `seconds`, whatever its scene."""
        return cls(seconds, seconds, 0.0)


def _organs(nodes: Iterable["pb.Node"]) -> int:
    return sum(1 for n in nodes if n.HasField("organ"))


def _enum(enum: "object", prefix: str, name: str, parameter: str) -> int:
    """The value of `prefix` + `name` in a protobuf enum; ValueError naming `parameter`."""
    labels = [n[len(prefix):].lower() for n in enum.keys()]  # type: ignore[attr-defined]
    if name.lower() not in labels:
        raise ValueError(f"{parameter}: {name!r} is not one of {', '.join(labels)}")
    return int(enum.Value(prefix + name.upper()))  # type: ignore[attr-defined]


def _curve_key(key: str) -> bytes:
    """A Z85 key given as its 40 characters or as a file holding them (server.public)."""
    if len(key) != 40 and os.path.isfile(key):
        with open(key) as f:
            key = f.read().strip()
    if len(key) != 40:
        raise ValueError(f"leaflux: a CurveZMQ key is 40 Z85 characters, not {key!r}")
    return key.encode()


class Client:
    """A connection to leafluxd at `endpoint`.

    Timeouts: `timeouts` (a Timeouts), or `status_timeout_s`, `scene_timeout_s` and
    `per_organ_s`; `timeout_s`, when given, is the wait of every request.
    `curve_server_key`: the daemon's CurveZMQ public key (Z85, or the path of
    server.public) when it binds beyond loopback.
    """

    def __init__(self, endpoint: str = DEFAULT_ENDPOINT, timeout_s: Optional[float] = None,
                 status_timeout_s: float = 30.0, scene_timeout_s: float = 60.0,
                 per_organ_s: float = 0.010, *, timeouts: Optional[Timeouts] = None,
                 curve_server_key: Optional[str] = None) -> None:
        self.endpoint = endpoint
        if timeouts is None:
            timeouts = (Timeouts.all(timeout_s) if timeout_s is not None
                        else Timeouts(status_timeout_s, scene_timeout_s, per_organ_s))
        self.timeouts = timeouts
        self._curve_server_key = _curve_key(curve_server_key) if curve_server_key else None
        self._context = zmq.Context.instance()
        self._socket: Optional[zmq.Socket] = None
        self._next_id = 1
        self._organs: Dict[str, int] = {}  # by session: organs sent, removals aside
        self._max_message_bytes: Optional[int] = None  # the daemon's, once asked (0: not told)
        self.reconnect()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: object) -> None:
        self.disconnect()

    def disconnect(self) -> None:
        """Closes the connection (sessions stay open in the daemon)."""
        if self._socket is not None:
            self._socket.close()
            self._socket = None

    def reconnect(self) -> None:
        """A new connection to the same endpoint: replies to the old one are never read."""
        self._max_message_bytes = None  # perhaps another daemon now
        self.disconnect()
        socket = self._context.socket(zmq.DEALER)
        socket.setsockopt(zmq.LINGER, 0)
        if "[" in self.endpoint:
            socket.setsockopt(zmq.IPV6, 1)
        if self._curve_server_key:
            public, secret = zmq.curve_keypair()
            socket.curve_serverkey = self._curve_server_key
            socket.curve_publickey, socket.curve_secretkey = public, secret
        socket.connect(self.endpoint)
        self._socket = socket

    def timeout_s(self, request: "pb.Request") -> float:
        """The seconds `request` waits for its reply."""
        kind = request.WhichOneof("body")
        if kind == "open_session":
            organs = _organs(request.open_session.scene.nodes)
        elif kind == "resync":
            organs = _organs(request.resync.scene.nodes)
        elif kind == "cycle":
            organs = (self._organs.get(request.cycle.session, 0)
                      + _organs(request.cycle.delta.added))
        elif kind == "render":  # the session's ray engine built, then the picture
            organs = self._organs.get(request.render.session, 0)
        else:
            return self.timeouts.status_s
        return self.timeouts.scene_s + self.timeouts.per_organ_s * organs

    def call(self, request: "pb.Request") -> "pb.Reply":
        """Sends a Request (its version and request_id set here), returns its Reply.

        Raises the DaemonError of the reply's code (e.g. UnknownSession) on an Error reply,
        RequestTimeout when none comes in time, TooLarge, unsent, for a request over the
        daemon's max_message_bytes."""
        if self._socket is None:
            self.reconnect()
        assert self._socket is not None
        kind = request.WhichOneof("body") or "request"
        request.version = pb.PROTOCOL_VERSION_CURRENT
        request_id = request.request_id = self._next_id
        self._next_id += 1
        timeout_s = self.timeout_s(request)
        payload = request.SerializeToString()
        # ZeroMQ cuts off, unanswered, a request over twice the daemon's limit: a large one
        # is checked against the limit first (asked once a connection).
        if len(payload) > 1 << 20 and kind != "status":
            if self._max_message_bytes is None:
                self._max_message_bytes = self.status().max_message_bytes
            if 0 < self._max_message_bytes < len(payload):
                raise TooLarge(
                    "ERROR_CODE_TOO_LARGE",
                    f"the request of {len(payload)} bytes exceeds the limit of leafluxd at "
                    f"{self.endpoint}, {self._max_message_bytes} bytes (--max-message-mb): "
                    "not sent", field=kind, endpoint=self.endpoint)
        self._socket.send_multipart([b"", payload])
        deadline = time.monotonic() + timeout_s
        while True:
            left_s = deadline - time.monotonic()
            if left_s <= 0 or not self._socket.poll(math.ceil(1000 * left_s)):
                if time.monotonic() < deadline:
                    continue  # woke early: the timeout never comes before the one asked for
                self.reconnect()  # a late reply must not answer the next request
                raise RequestTimeout(self.endpoint, kind, timeout_s)
            reply = pb.Reply()
            try:
                reply.ParseFromString(self._socket.recv_multipart()[-1])
            except Exception:  # noqa: BLE001 (not a Reply: not ours either)
                log.warning("leaflux: dropped a message from %s that is not a leaflux.v1.Reply",
                            self.endpoint)
                continue
            # Id 0: the daemon could not read the request's id (it did not decode).
            if reply.request_id == request_id or (reply.request_id == 0
                                                  and reply.HasField("error")):
                break
            log.debug("leaflux: dropped a stale reply (request_id %d, waiting for %d)",
                      reply.request_id, request_id)
        if reply.HasField("error"):
            raise from_reply(reply.error, self.endpoint)
        if kind == "cycle":
            session = request.cycle.session
            self._organs[session] = (self._organs.get(session, 0)
                                     + _organs(request.cycle.delta.added))
        return reply

    def open(self, scene: "pb.Scene", settings: Optional["pb.SolverSettings"] = None,
             species: str = "") -> str:
        """Opens a session for a pb.Scene (bands, optics, environment, sources, first
        nodes); returns its id."""
        request = pb.Request()
        request.open_session.scene.CopyFrom(scene)
        if settings is not None:
            request.open_session.settings.CopyFrom(settings)
        request.open_session.species = species
        session: str = self.call(request).opened.session
        self._organs[session] = _organs(scene.nodes)
        return session

    def resync(self, session: str, scene: "pb.Scene",
               settings: Optional["pb.SolverSettings"] = None, last_cycle: int = 0) -> None:
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

    def cycle(self, session: str, number: int, added: Iterable["pb.Node"] = (),
              updated: Iterable["pb.Node"] = (), removed: Iterable[int] = (),
              suns: Optional[Iterable["pb.Sun"]] = None, bands: Iterable[str] = (),
              leaves: bool = True, structures: bool = False,
              light_vectors: Optional[bool] = None,
              resync: Optional[ResyncFunction] = None) -> CycleLight:
        """Sends cycle `number` of `session`: the delta (nodes added, updated, ids removed
        with their subtree), new suns if given, and the outputs asked for (`bands`: empty
        for all); returns its light.

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
        if light_vectors is not None:
            c.outputs.light_vectors = light_vectors
        try:
            return CycleLight.from_proto(self.call(request).cycle)
        except LeafluxError as e:
            lost = isinstance(e, RequestTimeout) or e.code == "ERROR_CODE_UNKNOWN_SESSION"
            if resync is None or not lost:
                raise
            log.warning("leaflux: cycle %d of session %s: %s; reconnecting, resyncing and "
                        "sending it again", number, session, e)
        self.reconnect()
        scene, settings = resync()
        self.resync(session, scene, settings, last_cycle=number - 1)
        return CycleLight.from_proto(self.call(request).cycle)

    def render(self, session: str, eye: Sequence[float], look: Sequence[float],
               up: Sequence[float] = (0.0, 0.0, 1.0), fov_deg: float = 45.0,
               size: Tuple[int, int] = (1024, 768), quantity: str = "irradiance",
               side: str = "seen", band: str = "", rgb: Sequence[str] = (),
               value_range: Optional[Tuple[float, float]] = None, palette: str = "viridis",
               pixel_samples: int = 4, photons: bool = False, scale_bar: bool = False,
               north_arrow: bool = False) -> "pb.Picture":
        """A picture of `session`'s scene in the light its last cycle returned (that cycle
        must have asked for leaves), drawn by the daemon as `leaflux render` draws it.

        `quantity`: irradiance, absorbed, radiosity or colour (true colour from the `rgb`
        bands, default R, G, B); `side`: seen, upper, lower or both; `value_range`: (min, max) of the
        colour scale (default 0 to the largest value in view); `palette`: viridis or grey.
        The reply's `png` holds the PNG file's bytes, `caption`, `scale_min`, `scale_max`
        what the colour bar shows."""
        request = pb.Request()
        r = request.render
        r.session = session
        for field, point in (("eye", eye), ("look", look), ("up", up)):
            getattr(r.camera, field).CopyFrom(pb.Vec3(x=point[0], y=point[1], z=point[2]))
        r.camera.fov_deg = fov_deg
        r.width, r.height = size
        r.pixel_samples = pixel_samples
        # The names of `leaflux render --quantity`: colour is RENDER_QUANTITY_TRUE_COLOUR.
        r.quantity = _enum(pb.RenderQuantity, "RENDER_QUANTITY_",
                           "true_colour" if quantity == "colour" else quantity, "quantity")
        r.side = _enum(pb.RenderSide, "RENDER_SIDE_", side, "side")
        r.band = band
        r.rgb.extend(rgb)
        r.photons = photons
        if value_range is not None:
            r.range.min, r.range.max = value_range
        r.palette = _enum(pb.RenderPalette, "RENDER_PALETTE_", palette, "palette")
        r.scale_bar, r.north_arrow = scale_bar, north_arrow
        return self.call(request).picture

    def status(self, session: str = "") -> "pb.StatusReply":
        """The daemon's counts and limits (`session_count`, `max_message_bytes`, …), or one
        session's (`sessions[0]`: nodes, organs, cycles)."""
        request = pb.Request()
        request.status.session = session
        return self.call(request).status

    def close(self, session: str) -> None:
        """Frees a session in the daemon."""
        request = pb.Request()
        request.close_session.session = session
        self.call(request)
        self._organs.pop(session, None)

    def shutdown(self) -> None:
        """Stops the daemon, as SIGTERM does."""
        request = pb.Request()
        request.shutdown.SetInParent()
        self.call(request)
