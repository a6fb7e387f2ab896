"""Small helpers to build protocol messages."""
from __future__ import annotations

import os
from typing import Any, Optional, Sequence, Union

from . import leaflux_pb2 as pb


def frame(matrix: Sequence[Sequence[float]]) -> "pb.Frame":
    """A pb.Frame (parentFromLocal) from a 3×4 (or 4×4) row-major matrix of nested lists."""
    f = pb.Frame()
    f.m.extend(float(v) for row in matrix[:3] for v in row)
    return f


DAYLIGHT_PAR_UMOL_PER_J = 4.57
"""Photons per joule of daylight PAR (µmol J⁻¹, McCree 1972): W/m² × 4.57 = µmol m⁻² s⁻¹."""


def photon_umol_per_j(band: "pb.Band") -> Optional[float]:
    """The photons per joule (µmol J⁻¹) of a scene's band, as leafluxd and `leaflux solve`
    take it: the band's `photon_umol_per_j` when given, else 4.57 for a PAR band (named
    "PAR" in any case, or of 400–700 nm), else None. Multiply a BandLight's W/m² and W by
    it for µmol m⁻² s⁻¹ and µmol s⁻¹."""
    if band.photon_umol_per_j > 0:
        return band.photon_umol_per_j
    if band.name.lower() == "par" or (abs(band.wavelength_min_nm - 400) < 1
                                      and abs(band.wavelength_max_nm - 700) < 1):
        return DAYLIGHT_PAR_UMOL_PER_J
    return None


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
