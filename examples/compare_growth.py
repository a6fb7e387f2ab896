#!/usr/bin/python3
"""Compares two leaflux-grow runs of one scenario grown under other light (paper Fig. 15
and 19): per cycle, the structural distance between the plants, and each run's solve time
and daemon memory.

Phytomers are matched by their topological address (plant, axis path, rank: the same in
both runs however the node ids differ). The structural distance is the organ-by-organ
difference of mass, Σ |m_a − m_b| over every address (a phytomer one run lacks has mass 0
there), in % of the mean total mass ½ Σ (m_a + m_b): 0 for identical plants, 200 % for
plants sharing no organ. Per phytomer, the relative difference of its mass between the runs,
|m_a − m_b| / ½ (m_a + m_b), gives the distance's largest value and standard deviation over
the phytomers (paper Fig. 15: max and σ), a phytomer one run lacks counting 200 %.

Usage: compare_growth.py RUN_A LABEL_A RUN_B LABEL_B OUT_PREFIX
Writes OUT_PREFIX.csv and OUT_PREFIX.png.
"""
import argparse
import csv
import os
import sys
from collections import defaultdict


def phytomers(run):
    """{cycle: {address: (internode g, leaf g)}} from a run's phytomers.csv."""
    by_cycle = defaultdict(dict)
    for row in csv.DictReader(open(os.path.join(run, "phytomers.csv"))):
        by_cycle[int(row["cycle"])][row["address"]] = (float(row["internode_g"]), float(row["leaf_g"]))
    return by_cycle


def cycles(run):
    return {int(r["cycle"]): r for r in csv.DictReader(open(os.path.join(run, "cycles.csv")))}


def distance(a, b):
    """(structural distance %, leaf-only distance %, phytomers in one run only)."""
    def part(index):
        diff = sum(abs(a.get(k, (0, 0))[index] - b.get(k, (0, 0))[index]) for k in a.keys() | b.keys())
        mean = 0.5 * (sum(v[index] for v in a.values()) + sum(v[index] for v in b.values()))
        return diff, mean
    (di, mi), (dl, ml) = part(0), part(1)
    total = 100 * (di + dl) / (mi + ml) if mi + ml > 0 else 0.0
    leaves = 100 * dl / ml if ml > 0 else 0.0
    return total, leaves, len(a.keys() ^ b.keys())


def per_phytomer(a, b):
    """(largest, standard deviation) over phytomers of their masses' relative difference, %."""
    values = []
    for k in a.keys() | b.keys():
        ma, mb = sum(a.get(k, (0, 0))), sum(b.get(k, (0, 0)))
        values.append(200 * abs(ma - mb) / (ma + mb) if ma + mb > 0 else 0.0)
    if not values:
        return 0.0, 0.0
    mean = sum(values) / len(values)
    return max(values), (sum((v - mean) ** 2 for v in values) / len(values)) ** 0.5


def main():
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("run_a", help="the first run's folder (leaflux-grow --out)")
    parser.add_argument("label_a", help="its label in the plot")
    parser.add_argument("run_b", help="the second run's folder")
    parser.add_argument("label_b", help="its label")
    parser.add_argument("out_prefix", help="writes OUT_PREFIX.csv and OUT_PREFIX.png")
    args = parser.parse_args()
    run_a, label_a, run_b, label_b, prefix = (args.run_a, args.label_a, args.run_b, args.label_b,
                                              args.out_prefix)
    pa, pb, ca, cb = phytomers(run_a), phytomers(run_b), cycles(run_a), cycles(run_b)
    rows = []
    for c in sorted(pa.keys() & pb.keys()):
        total, leaves, unmatched = distance(pa[c], pb[c])
        largest, sigma = per_phytomer(pa[c], pb[c])
        rows.append(dict(cycle=c, structural_distance_pct=round(total, 3), leaf_distance_pct=round(leaves, 3),
                         phytomer_distance_max_pct=round(largest, 3), phytomer_distance_sd_pct=round(sigma, 3),
                         phytomers_in_one_run=unmatched,
                         **{f"phytomers_{label}": len(p[c]) for label, p in ((label_a, pa), (label_b, pb))},
                         **{f"solve_s_{label}": cc[c]["solve_s"] for label, cc in ((label_a, ca), (label_b, cb))},
                         **{f"daemon_peak_mib_{label}": cc[c]["daemon_peak_mib"]
                            for label, cc in ((label_a, ca), (label_b, cb))}))
    with open(prefix + ".csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    last = rows[-1]
    print(f"{label_a} against {label_b}: after {last['cycle']} cycles the structural distance is "
          f"{last['structural_distance_pct']:.1f} % ({last['phytomers_in_one_run']} phytomers in one run only); "
          f"mean solve {sum(float(r['solve_s_' + label_a]) for r in rows) / len(rows):.3f} s against "
          f"{sum(float(r['solve_s_' + label_b]) for r in rows) / len(rows):.3f} s")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plot", file=sys.stderr)
        return
    x = [r["cycle"] for r in rows]
    fig, axes = plt.subplots(1, 3, figsize=(14, 3.8))
    axes[0].plot(x, [r["structural_distance_pct"] for r in rows], marker=".", label="all organs")
    axes[0].plot(x, [r["leaf_distance_pct"] for r in rows], marker=".", label="leaves")
    axes[0].plot(x, [r["phytomer_distance_max_pct"] for r in rows], ls="--", label="phytomers: max")
    axes[0].plot(x, [r["phytomer_distance_sd_pct"] for r in rows], ls=":", label="phytomers: σ")
    axes[0].set_ylabel(f"distance, {label_a} vs {label_b} (%)")
    axes[0].legend()
    for label in (label_a, label_b):
        axes[1].plot(x, [float(r["solve_s_" + label]) for r in rows], marker=".", label=label)
        axes[2].plot(x, [float(r["daemon_peak_mib_" + label]) for r in rows], marker=".", label=label)
    axes[1].set_ylabel("solve time (s)")
    axes[2].set_ylabel("daemon peak memory (MiB)")
    for ax in axes:
        ax.set_xlabel("cycle")
        ax.grid(True, alpha=0.3)
    axes[1].legend()
    axes[2].legend()
    fig.tight_layout()
    fig.savefig(prefix + ".png", dpi=100)
    print(f"wrote {prefix}.csv and {prefix}.png")


if __name__ == "__main__":
    main()
