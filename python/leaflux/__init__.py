"""leaflux: a Python client of leafluxd, the lighting daemon of plant-growth co-simulation.

    from leaflux import Client, LocalDaemon, pb
    with LocalDaemon() as daemon, Client(daemon.endpoint) as client:
        session = client.open(scene, pb.SolverSettings(solver=pb.SOLVER_KIND_HRC))
        light = client.cycle(session, 1, added=[...], bands=["PAR"])
        light.to_csv("out/cycle1.csv")  # its folder made first: os.makedirs("out", exist_ok=True)

`pb` is the protocol's generated module (leaflux_pb2, from proto/leaflux.proto); `policy_pb2`
is proto/policy.proto's. See docs/python.md.
"""
import os as _os

from . import _generate

_here = _os.path.dirname(_os.path.abspath(__file__))
_source_protos = _os.path.join(_here, "..", "..", "proto")
# Imported from a checkout (python/leaflux): the modules are generated in place, and again
# when a .proto is newer.
if _os.path.isfile(_os.path.join(_source_protos, "leaflux.proto")) and _generate.stale(
        _source_protos, _here):
    _generate.generate(_source_protos, _here)

try:
    from . import leaflux_pb2, policy_pb2
except ImportError as _e:  # pragma: no cover
    raise ImportError(
        "leaflux: the generated leaflux_pb2 module is missing; install the package with "
        "pip (pip install ./python in a leaflux checkout), which runs protoc") from _e

pb = leaflux_pb2

from .client import DEFAULT_ENDPOINT, Client, Timeouts  # noqa: E402
from .daemon import LocalDaemon, find_leafluxd  # noqa: E402
from .errors import (ERROR_CLASSES, AlreadyExists, DaemonError, DaemonStartError,  # noqa: E402
                     Degenerate, FileError, InternalError, InvalidArgument, LeafluxError,
                     NotFound, ParentCycle, ParseError, RequestTimeout, ShuttingDown,
                     TooLarge, UnknownSession, Unsupported)
from .results import (CSV_COLUMNS, BandLight, CycleLight, EnergyBalance, OrganLight,  # noqa: E402
                      SolveStatistics, StructureLight, Vector)
from .scene import (DAYLIGHT_PAR_UMOL_PER_J, band_light, frame, photon_umol_per_j,  # noqa: E402
                    read_scene)

__version__ = "0.1.0"

__all__ = [
    "pb", "leaflux_pb2", "policy_pb2", "photon_umol_per_j", "DAYLIGHT_PAR_UMOL_PER_J", "Client", "Timeouts", "DEFAULT_ENDPOINT",
    "LocalDaemon", "find_leafluxd", "LeafluxError", "DaemonError", "RequestTimeout",
    "DaemonStartError", "InvalidArgument", "NotFound", "AlreadyExists", "Degenerate",
    "ParentCycle", "ParseError", "FileError", "Unsupported", "UnknownSession", "TooLarge",
    "ShuttingDown", "InternalError", "ERROR_CLASSES", "CycleLight", "OrganLight",
    "StructureLight", "BandLight", "Vector", "SolveStatistics", "EnergyBalance",
    "CSV_COLUMNS", "band_light", "frame", "read_scene",
]
