#!/usr/bin/python3
"""Coupling a foreign growth model to leafluxd: a rosette written in a few lines of Python
sends its own deltas and grows from the light it gets back.

Each cycle (a day) the rosette makes a new leaf (a flat blade at the golden angle, raised
20°). What the plant makes from the PAR it absorbed (radiation use efficiency) goes, a
share of it, to its leaves, which expand towards their final size as a lettuce's do: each
leaf asks what its logistic expansion would take, and gets it in full when the plant makes
enough, a share of it when not. Only the new leaf is added and only the leaves that grew
are updated (their frame's scale changes). Twelve leaves make a rosette of about 0.06 m²
and 4 g of dry matter.

A daemon that restarts, or a cycle that goes unanswered, costs nothing but time: the
script keeps the nodes the daemon has lit and hands them back (Client.cycle's `resync`).

Usage: foreign_growth.py [--endpoint tcp://…] [--cycles 12]   (no endpoint: starts leafluxd)
                         [--samples N] (Monte Carlo instead of HRC) [--csv rows.csv]
"""
import argparse
import math

from leaflux_client import Client, LocalDaemon, band_light, frame, pb

# Radiation use efficiency (g of dry matter per MJ of PAR absorbed), light hours a day,
# specific leaf area (m² of leaf per g), the share of dry matter the leaves get (the rest:
# roots and stem), a leaf's area when it appears and when grown (m²), and its relative
# expansion rate while small (per day): lettuce-like values.
RUE_G_PER_MJ, LIGHT_HOURS, SLA_M2_PER_G, LEAF_SHARE = 2.5, 8.0, 0.03, 0.5
NEW_LEAF_M2, FINAL_LEAF_M2, EXPANSION_PER_DAY = 0.0005, 0.012, 0.45


def scene():
    s = pb.Scene(version=pb.PROTOCOL_VERSION_CURRENT)
    s.bands.add(name="PAR", wavelength_min_nm=400, wavelength_max_nm=700)
    leaf = s.optics.add(id="leaf")
    leaf.bands["PAR"].CopyFrom(pb.BandOptics(rho_upper=0.1, rho_lower=0.1, tau_upper=0.05, tau_lower=0.05))
    ground = s.optics.add(id="ground")
    ground.bands["PAR"].CopyFrom(pb.BandOptics(rho_upper=0.1, rho_lower=0.1))
    # A unit blade from the origin along +x, upper side up; frames scale it.
    s.meshes["blade"].positions.extend([0, 0, 0, 0.5, -0.25, 0, 1, 0, 0, 0.5, 0.25, 0])
    s.meshes["blade"].triangles.extend([0, 1, 2, 0, 2, 3])
    g = s.environment.add(name="ground", optics="ground")
    g.mesh.positions.extend([-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, 2, 0])
    g.mesh.triangles.extend([0, 1, 2, 0, 2, 3])
    sun = s.suns.add()
    sun.direction.x, sun.direction.y, sun.direction.z = 0.3, 0.4, 0.866
    sun.normal_irradiance["PAR"] = 400
    s.sky.model = pb.SKY_MODEL_CIE_OVERCAST
    s.sky.horizontal_irradiance["PAR"] = 80
    s.sky.discretization = pb.SKY_DISCRETIZATION_TURTLE_46
    s.nodes.add(id=1, parent=0, type=pb.NODE_TYPE_PLANT, name="rosette")
    return s


def leaf_node(index, area_m2):
    """Leaf `index` of the rosette: at the golden angle, raised 20°, scaled to its area."""
    azimuth, raise_ = math.radians(137.5 * index), math.radians(20)
    length = math.sqrt(area_m2 / 0.25)  # the unit blade has an area of 0.25 and width / length 0.5
    ca, sa, cr, sr = math.cos(azimuth), math.sin(azimuth), math.cos(raise_), math.sin(raise_)
    # Rz(azimuth) · Ry(−raise) · S(length, length, 1), 1 cm above the ground.
    m = [[ca * cr * length, -sa * length, -ca * sr, 0.0],
         [sa * cr * length, ca * length, -sa * sr, 0.0],
         [sr * length, 0.0, cr, 0.01 + 0.002 * index]]
    node = pb.Node(id=100 + index, parent=1, type=pb.NODE_TYPE_LEAF, name=f"leaf{index}")
    node.frame.CopyFrom(frame(m))
    node.organ.mesh_ref, node.organ.optics = "blade", "leaf"
    return node


def grow(client, cycles, settings, csv=None):
    session = client.open(scene(), settings, "rosette")
    areas = []  # m², per leaf
    new, changed = [], []
    lit = {}  # the leaves as the daemon last lit them, by node id

    def as_before():  # the session's scene before the cycle under way, to resync it
        s = scene()
        s.nodes.extend(lit[node] for node in sorted(lit))
        return s, settings

    print(f"{'cycle':>5} {'leaves':>6} {'area_m2':>8} {'absorbed_W':>10} {'biomass_g':>9} {'sent':>5}",
          flush=True)
    rows = open(csv, "w") if csv else None
    biomass = 0.0
    for number in range(1, cycles + 1):
        areas.append(NEW_LEAF_M2)  # a new leaf each cycle
        new = [leaf_node(len(areas) - 1, areas[-1])]
        result = client.cycle(session, number, added=new, updated=changed, bands=["PAR"],
                              resync=as_before)
        lit.update((n.id, n) for n in new + changed)
        absorbed = {o.node: band_light(o, "PAR").absorbed_w for o in result.organs if o.node >= 100}
        assert len(absorbed) == len(areas), "every leaf gets its light"
        total = sum(absorbed.values())
        produced = RUE_G_PER_MJ * total * LIGHT_HOURS * 3600 * 1e-6
        biomass += produced
        # Each leaf's logistic expansion is its demand; the leaves' share of what the plant
        # made is the supply, shared in proportion to the demands when it falls short.
        demand = [EXPANSION_PER_DAY * a * (1 - a / FINAL_LEAF_M2) for a in areas]
        supply = SLA_M2_PER_G * LEAF_SHARE * produced
        served = min(1.0, supply / sum(demand)) if sum(demand) > 0 else 0.0
        changed = []
        for i, wanted in enumerate(demand):
            if wanted * served > 1e-7:
                areas[i] += wanted * served
                changed.append(leaf_node(i, areas[i]))
        print(f"{number:>5} {len(areas):>6} {sum(areas):>8.4f} {total:>10.3f} {biomass:>9.3f} "
              f"{len(new) + len(changed):>5}", flush=True)
        if rows:
            rows.write(f"{number},{len(areas)},{sum(areas)!r},{total!r},{biomass!r}\n")
    client.close(session)
    if rows:
        rows.close()


def main():
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("--endpoint", help="a running leafluxd, e.g. tcp://127.0.0.1:5555 "
                        "(default: start one, $LEAFLUX_BUILD/server/leafluxd or on PATH)")
    parser.add_argument("--cycles", type=int, default=12, help="cycles to grow (default 12)")
    parser.add_argument("--samples", type=int, help="Monte Carlo paths per leaf (default: HRC)")
    parser.add_argument("--cycle-timeout", type=float, default=60.0,
                        help="seconds to wait for a cycle's light before resyncing (default 60)")
    parser.add_argument("--csv", help="write a row per cycle, at full precision, to this file "
                        "(default: none)")
    args = parser.parse_args()
    settings = pb.SolverSettings(solver=pb.SOLVER_KIND_HRC, epsilon=1e-4)
    if args.samples:
        settings = pb.SolverSettings(solver=pb.SOLVER_KIND_MONTE_CARLO, samples=args.samples)
    if args.endpoint:
        with Client(args.endpoint, scene_timeout_s=args.cycle_timeout) as client:
            grow(client, args.cycles, settings, args.csv)
    else:
        with LocalDaemon() as daemon, Client(daemon.endpoint,
                                             scene_timeout_s=args.cycle_timeout) as client:
            grow(client, args.cycles, settings, args.csv)


if __name__ == "__main__":
    main()
