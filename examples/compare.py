#!/usr/bin/python3
"""Compares per-leaf results of two solvers: `compare.py REFERENCE.csv OTHER.csv`.
Prints, per band, the L2 error in % of the reference maximum (Soler 2003, Fig. 14), the
mean and 95th-percentile relative errors over lit leaves (5 % of the brightest or more),
what all the leaves' upper and lower sides take together against the reference's (a
solver that sends scattered light the wrong way shows on one side), and the mean signed
error of each fifth of the leaves from the darkest to the brightest
(in % of the maximum): a solver that spreads light too evenly is high in the first fifths
and low in the last. With `--scene SCENE --by TYPE`, the L2 error split into the part the
leaves of one structure share (each structure's mean error: the smallest structure of TYPE
holding the leaf, with at least --min-leaves leaves) and the part within structures;
their squares add up to the whole's: a solver that shares light out wrongly between
structures, as instancing may between its instances, shows in the first."""
import argparse
import collections
import csv
import math
import os
import sys

LIT = 0.05


def load(path):
    """Leaf area (m²) and irradiance on its upper and lower sides (W/m²) by (organ, band)."""
    values = {}
    for row in csv.DictReader(open(path)):
        if row["organ"].startswith("leaf"):
            values[(row["organ"], row["band"])] = (float(row["area_m2"]),
                                                   float(row["irradiance_upper_wm2"]),
                                                   float(row["irradiance_lower_wm2"]))
    return values


def both_sides(leaves):
    """Leaf irradiance, both sides together (W/m²), by (organ, band)."""
    return {k: upper + lower for k, (_, upper, lower) in leaves.items()}


def sides_against(reference, value, band):
    """(upper, lower): what all the leaves' sides take, in % off the reference's."""
    keys = [k for k in reference if k[1] == band]
    return tuple(100 * (sum(value[k][0] * value[k][s] for k in keys) /
                        sum(reference[k][0] * reference[k][s] for k in keys) - 1)
                 for s in (1, 2))


def errors(reference, value, band):
    """(L2 % of max, mean relative %, 95th-percentile relative %) over one band's leaves."""
    keys = [k for k in reference if k[1] == band]
    largest = max(reference[k] for k in keys)
    l2 = math.sqrt(sum((value[k] - reference[k]) ** 2 for k in keys) / len(keys)) / largest
    relative = sorted(abs(value[k] - reference[k]) / reference[k] for k in keys if reference[k] >= LIT * largest)
    mean = sum(relative) / len(relative)
    p95 = relative[min(len(relative) - 1, int(0.95 * len(relative)))]
    return 100 * l2, 100 * mean, 100 * p95


def bias_by_fifth(reference, value, band):
    """Mean signed error (% of max) of each fifth of the leaves, darkest first."""
    keys = sorted((k for k in reference if k[1] == band), key=lambda k: reference[k])
    largest = reference[keys[-1]]
    fifths = [keys[len(keys) * i // 5:len(keys) * (i + 1) // 5] for i in range(5)]
    return [100 * sum(value[k] - reference[k] for k in f) / len(f) / largest for f in fifths if f]


def structure_of_leaves(path, by, least):
    """Leaf name -> the name of the smallest node of type `by` above it holding at least
    `least` leaves (None where there is none)."""
    python = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python")
    if python not in sys.path:
        sys.path.insert(0, python)
    from leaflux.scene import read_scene  # noqa: E402
    from leaflux import leaflux_pb2 as pb  # noqa: E402
    scene = read_scene(path)
    nodes = {n.id: n for n in scene.nodes}
    kind = pb.NodeType.Value("NODE_TYPE_" + by.upper())
    leaves = collections.Counter()
    for n in scene.nodes:
        if n.type == pb.NODE_TYPE_LEAF:
            p = n.parent
            while p in nodes:
                leaves[p] += 1
                p = nodes[p].parent
    holder = {}
    for n in scene.nodes:
        if n.type != pb.NODE_TYPE_LEAF:
            continue
        p = n.parent
        while p in nodes and not (nodes[p].type == kind and leaves[p] >= least):
            p = nodes[p].parent
        holder[n.name] = nodes[p].name if p in nodes else None
    return holder


def split_by_structure(reference, value, band, holder):
    """(between, within, structures): the L2 error (% of max) of the structures' mean
    errors and of what is left, over one band's leaves."""
    keys = [k for k in reference if k[1] == band]
    largest = max(reference[k] for k in keys)
    groups = collections.defaultdict(list)
    for k in keys:
        groups[holder.get(k[0])].append(value[k] - reference[k])
    total = sum(d * d for g in groups.values() for d in g)
    between = sum(len(g) * (sum(g) / len(g)) ** 2 for g in groups.values())
    scale = 100 / largest / math.sqrt(len(keys))
    return scale * math.sqrt(between), scale * math.sqrt(max(total - between, 0.0)), len(groups)


def main():
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split()))
    parser.add_argument("reference", help="per-leaf CSV of the reference (leaflux solve --out)")
    parser.add_argument("other", help="per-leaf CSV of the solver compared with it")
    parser.add_argument("--scene", help="the scene file both solved, to split the error by structure")
    parser.add_argument("--by", default="axis", choices=["plant", "axis", "phytomer"],
                        help="with --scene: the type of structure (default axis)")
    parser.add_argument("--min-leaves", type=int, default=11,
                        help="with --scene: the least leaves a structure holds (default 11, "
                             "the default policy's smallest instance)")
    args = parser.parse_args()
    reference_leaves, value_leaves = load(args.reference), load(args.other)
    reference, value = both_sides(reference_leaves), both_sides(value_leaves)
    holder = structure_of_leaves(args.scene, args.by, args.min_leaves) if args.scene else None
    for band in sorted({k[1] for k in reference}):
        l2, mean, p95 = errors(reference, value, band)
        print(f"{band}: L2 {l2:.2f} % of max, mean relative {mean:.2f} %, 95th percentile {p95:.2f} %")
        upper, lower = sides_against(reference_leaves, value_leaves, band)
        print(f"{band}: all upper sides {upper:+.2f} %, all lower sides {lower:+.2f} % "
              f"against the reference")
        fifths = " ".join(f"{b:+.2f}" for b in bias_by_fifth(reference, value, band))
        print(f"{band}: mean signed error by fifth, darkest to brightest (% of max): {fifths}")
        if holder is not None:
            between, within, count = split_by_structure(reference, value, band, holder)
            print(f"{band}: L2 between {count} structures {between:.2f} %, within them {within:.2f} %")


if __name__ == "__main__":
    main()
