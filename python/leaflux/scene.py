"""Small helpers to build protocol messages."""
from __future__ import annotations

import os
from typing import Any, Sequence, Union

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


def read_scene(path: Union[str, "os.PathLike[str]"]) -> "pb.Scene":
    """A pb.Scene from a scene file: protobuf text format (.txtpb, .pbtxt, .txt), binary
    otherwise. (OBJ, .can and OPF imports are the daemon's and `leaflux`'s.)"""
    from google.protobuf import text_format
    name = os.fspath(path)
    scene = pb.Scene()
    if name.endswith((".txtpb", ".pbtxt", ".txt")):
        with open(name) as f:
            try:
                text_format.Parse(f.read(), scene)
            except text_format.ParseError as e:
                raise ValueError(f"{name}:{e}") from None
    else:
        with open(name, "rb") as f:
            scene.ParseFromString(f.read())
    return scene
