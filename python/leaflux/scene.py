"""Small helpers to build protocol messages."""
from __future__ import annotations

from typing import Any, Sequence

from . import leaflux_pb2 as pb


def frame(matrix: Sequence[Sequence[float]]) -> "pb.Frame":
    """A pb.Frame (parentFromLocal) from a 3×4 (or 4×4) row-major matrix of nested lists."""
    f = pb.Frame()
    f.m.extend(float(v) for row in matrix[:3] for v in row)
    return f


def band_light(organ: Any, band: str) -> Any:
    """The light of `band` in an organ or structure: a BandLight of leaflux.results, or a
    pb.BandLight of a pb.OrganLight / pb.StructureLight. KeyError if there is none."""
    for b in organ.bands:
        if b.band == band:
            return b
    raise KeyError(f"no band {band!r} in the light of {organ.name or organ.node}")
