"""A cycle's light as plain objects, CSV rows or a pandas DataFrame.

The names are the protocol's (leaflux.v1.CycleResult), units in the names: irradiance in
W/m² on each side of an organ, absorbed power in W, areas in m²; for a band with a photon
unit (PAR) the same in µmol m⁻² s⁻¹ and µmol s⁻¹.
"""
from __future__ import annotations

import csv
import os
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, NamedTuple, Optional, Union

from . import leaflux_pb2 as pb

PathLike = Union[str, "os.PathLike[str]"]


class Vector(NamedTuple):
    """A 3-vector: a tuple with .x, .y, .z."""
    x: float
    y: float
    z: float


@dataclass
class BandLight:
    """The light of one band on an organ or structure. `light_vector` is None when the
    cycle asked for none; `stderr_*` are -1 when the solver gives no estimate (HRC). The
    photon figures (µmol m⁻² s⁻¹, µmol s⁻¹: the W figures times the band's
    photon_umol_per_j, 4.57 for PAR) are None for a band without a photon unit."""
    band: str
    irradiance_upper_wm2: float
    irradiance_lower_wm2: float
    absorbed_w: float
    light_vector: Optional[Vector] = None
    stderr_upper_wm2: float = -1.0
    stderr_lower_wm2: float = -1.0
    photon_irradiance_upper_umol_m2_s: Optional[float] = None
    photon_irradiance_lower_umol_m2_s: Optional[float] = None
    absorbed_umol_s: Optional[float] = None

    @classmethod
    def from_proto(cls, b: "pb.BandLight") -> "BandLight":
        vector = (Vector(b.light_vector.x, b.light_vector.y, b.light_vector.z)
                  if b.HasField("light_vector") else None)

        def photons(name: str) -> Optional[float]:  # unset: the band has no photon unit
            return getattr(b, name) if b.HasField(name) else None
        return cls(b.band, b.irradiance_upper_wm2, b.irradiance_lower_wm2, b.absorbed_w,
                   vector, b.stderr_upper_wm2, b.stderr_lower_wm2,
                   photons("photon_irradiance_upper_umol_m2_s"),
                   photons("photon_irradiance_lower_umol_m2_s"), photons("absorbed_umol_s"))


def _band(bands: List[BandLight], band: str, owner: str) -> BandLight:
    for b in bands:
        if b.band == band:
            return b
    raise KeyError(f"no band {band!r} in the light of {owner} "
                   f"(bands: {', '.join(b.band for b in bands) or 'none'})")


@dataclass
class OrganLight:
    """One organ's light: `node` (0 for environment surfaces and emitters), `name`,
    `area_m2` and a BandLight per band solved."""
    node: int
    name: str
    area_m2: float
    bands: List[BandLight] = field(default_factory=list)

    def band(self, band: str) -> BandLight:
        """The BandLight of `band` (KeyError naming the bands there are otherwise)."""
        return _band(self.bands, band, self.name or f"node {self.node}")

    @classmethod
    def from_proto(cls, o: "pb.OrganLight") -> "OrganLight":
        return cls(o.node, o.name, o.area_m2, [BandLight.from_proto(b) for b in o.bands])


@dataclass
class StructureLight:
    """The light of a plant, axis or phytomer, aggregated over its `organs` organs; `type`
    is the NodeType's name (e.g. "NODE_TYPE_PLANT")."""
    node: int
    name: str
    type: str
    organs: int
    area_m2: float
    bands: List[BandLight] = field(default_factory=list)

    def band(self, band: str) -> BandLight:
        return _band(self.bands, band, self.name or f"node {self.node}")

    @classmethod
    def from_proto(cls, s: "pb.StructureLight") -> "StructureLight":
        return cls(s.node, s.name, pb.NodeType.Name(s.type), s.organs, s.area_m2,
                   [BandLight.from_proto(b) for b in s.bands])


@dataclass
class EnergyBalance:
    band: str
    incident_w: float
    absorbed_w: float
    escaped_w: float


@dataclass
class SolveStatistics:
    """What the solve cost; `reused`: the light of the cycle before, not solved again."""
    wall_seconds: float = 0.0
    cpu_seconds: float = 0.0
    peak_rss_bytes: int = 0
    rays: int = 0
    links: int = 0
    elements: int = 0
    iterations: int = 0
    residual: float = 0.0
    threads: int = 0
    reused: bool = False
    balance: List[EnergyBalance] = field(default_factory=list)

    @classmethod
    def from_proto(cls, s: "pb.SolveStatistics") -> "SolveStatistics":
        return cls(s.wall_seconds, s.cpu_seconds, s.peak_rss_bytes, s.rays, s.links,
                   s.elements, s.iterations, s.residual, s.threads, s.reused,
                   [EnergyBalance(b.band, b.incident_w, b.absorbed_w, b.escaped_w)
                    for b in s.balance])


CSV_COLUMNS = ["cycle", "kind", "node", "name", "type", "organs", "area_m2", "band",
               "irradiance_upper_wm2", "irradiance_lower_wm2", "absorbed_w",
               "light_vector_x", "light_vector_y", "light_vector_z",
               "stderr_upper_wm2", "stderr_lower_wm2", "photon_irradiance_upper_umol_m2_s",
               "photon_irradiance_lower_umol_m2_s", "absorbed_umol_s"]
"""The columns of CycleLight.to_csv and to_dataframe: a row per organ (kind "organ") or
structure (kind "structure") and band. Empty light_vector_* when none was asked for, empty
photon columns for a band without a photon unit; the photon columns are last, in the order
of `leaflux solve --out`."""


@dataclass
class CycleLight:
    """A cycle's light: `organs` (when the cycle asked for leaves), `structures` (when it
    asked for structures), `statistics`; `proto` is the reply's CycleResult as received."""
    session: str
    number: int
    organs: List[OrganLight] = field(default_factory=list)
    structures: List[StructureLight] = field(default_factory=list)
    statistics: SolveStatistics = field(default_factory=SolveStatistics)
    proto: Optional["pb.CycleResult"] = field(default=None, repr=False, compare=False)

    @classmethod
    def from_proto(cls, r: "pb.CycleResult") -> "CycleLight":
        return cls(r.session, r.number, [OrganLight.from_proto(o) for o in r.organs],
                   [StructureLight.from_proto(s) for s in r.structures],
                   SolveStatistics.from_proto(r.statistics), r)

    def organ(self, node: int) -> OrganLight:
        """The organ of node id `node` (KeyError if the reply has none)."""
        for o in self.organs:
            if o.node == node:
                return o
        raise KeyError(f"no organ of node {node} in cycle {self.number}")

    def absorbed_w(self, band: str, plants_only: bool = True) -> float:
        """The power absorbed in `band`, W, by the organs (environment surfaces, node 0,
        left out unless plants_only is False)."""
        return sum(o.band(band).absorbed_w for o in self.organs
                   if o.node or not plants_only)

    def rows(self) -> List[Dict[str, Any]]:
        """A dict per organ or structure and band, keyed by CSV_COLUMNS."""
        rows: List[Dict[str, Any]] = []
        items: Iterable[Union[OrganLight, StructureLight]] = [*self.organs, *self.structures]
        for item in items:
            kind, type_, organs = (("structure", item.type, item.organs)
                                   if isinstance(item, StructureLight) else ("organ", "", 1))
            for b in item.bands:
                v = b.light_vector
                rows.append({
                    "cycle": self.number, "kind": kind,
                    "node": item.node, "name": item.name, "type": type_, "organs": organs,
                    "area_m2": item.area_m2, "band": b.band,
                    "irradiance_upper_wm2": b.irradiance_upper_wm2,
                    "irradiance_lower_wm2": b.irradiance_lower_wm2,
                    "absorbed_w": b.absorbed_w,
                    "light_vector_x": v.x if v else None,
                    "light_vector_y": v.y if v else None,
                    "light_vector_z": v.z if v else None,
                    "stderr_upper_wm2": b.stderr_upper_wm2,
                    "stderr_lower_wm2": b.stderr_lower_wm2,
                    "photon_irradiance_upper_umol_m2_s": b.photon_irradiance_upper_umol_m2_s,
                    "photon_irradiance_lower_umol_m2_s": b.photon_irradiance_lower_umol_m2_s,
                    "absorbed_umol_s": b.absorbed_umol_s,
                })
        return rows

    def to_csv(self, path: PathLike) -> None:
        """Writes rows() as CSV with a header, at full precision (read_csv reads it back)."""
        with open(path, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=CSV_COLUMNS)
            writer.writeheader()
            for row in self.rows():
                writer.writerow({k: "" if v is None else (repr(v) if isinstance(v, float) else v)
                                 for k, v in row.items()})

    @classmethod
    def read_csv(cls, path: PathLike, session: str = "") -> "CycleLight":
        """A CycleLight from a file of to_csv (one cycle; no statistics)."""
        organs: Dict[Any, OrganLight] = {}
        structures: Dict[int, StructureLight] = {}
        number = 0

        def optional(row: Dict[str, str], column: str) -> Optional[float]:
            # Empty, or missing in a file written before the column was: None.
            return float(row[column]) if row.get(column) else None
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                number = int(row["cycle"])
                node = int(row["node"])
                vector = (Vector(float(row["light_vector_x"]), float(row["light_vector_y"]),
                                 float(row["light_vector_z"]))
                          if row["light_vector_x"] else None)
                light = BandLight(row["band"], float(row["irradiance_upper_wm2"]),
                                  float(row["irradiance_lower_wm2"]), float(row["absorbed_w"]),
                                  vector, float(row["stderr_upper_wm2"]),
                                  float(row["stderr_lower_wm2"]),
                                  optional(row, "photon_irradiance_upper_umol_m2_s"),
                                  optional(row, "photon_irradiance_lower_umol_m2_s"),
                                  optional(row, "absorbed_umol_s"))
                if row["kind"] == "structure":
                    s = structures.setdefault(node, StructureLight(
                        node, row["name"], row["type"], int(row["organs"]),
                        float(row["area_m2"])))
                    s.bands.append(light)
                else:
                    # Environment surfaces all have node 0: keyed by name too.
                    o = organs.setdefault((node, row["name"]), OrganLight(node, row["name"],
                                                          float(row["area_m2"])))
                    o.bands.append(light)
        return cls(session, number, list(organs.values()), list(structures.values()))

    def to_dataframe(self) -> Any:
        """rows() as a pandas DataFrame (columns CSV_COLUMNS). Needs pandas, imported only
        here: ImportError saying how to install it otherwise."""
        return _pandas().DataFrame(self.rows(), columns=CSV_COLUMNS)


def _pandas() -> Any:
    try:
        import pandas
    except ImportError as e:
        raise ImportError(
            "leaflux: to_dataframe() needs pandas, which is not installed (Debian: "
            "apt install python3-pandas; otherwise pip install pandas); to_csv() and "
            "rows() need nothing more") from e
    return pandas

