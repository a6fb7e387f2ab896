#!/usr/bin/python3
"""Plots the Fig. 8 slices of leaflux_bench_phase_spread (Soler 2003 §4.1).

Reads phase_slices.csv: per group of a signature, its sampled members' phase functions from
a lateral direction (θin = φin = π/2 in the structure's frame) towards lateral outputs
(θout = π/2, φout from 0 to 360°), per unit leaf area so that sizes compare. Draws one
colour per group: its representative as a thick line, its other members as thin ones.

Usage: plot_phase_spread.py SLICES_CSV OUT_PNG [--band NIR]
"""
import argparse
import csv
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("slices", help="phase_slices.csv of leaflux_bench_phase_spread")
    parser.add_argument("png", help="the plot to write")
    parser.add_argument("--band", default="NIR", help="band to plot (default: NIR)")
    args = parser.parse_args()

    # signature → node → (representative, leaves, [(φ, f)])
    curves = defaultdict(dict)
    for r in csv.DictReader(open(args.slices)):
        if r["band"] != args.band:
            continue
        member = curves[r["signature"]].setdefault(
            r["node"], [r["representative"] == "1", int(r["leaves"]), []])
        member[2].append((float(r["phi_out_deg"]), float(r["f_per_leaf_area_per_sr"])))
    if not curves:
        raise SystemExit(f"{args.slices} has no rows of band {args.band}")

    types = sorted({s.split("|")[0] for s in curves})
    fig, axes = plt.subplots(1, len(types), figsize=(6.5 * len(types), 6), squeeze=False)
    colours = plt.get_cmap("tab10")
    for ax, kind in zip(axes[0], types):
        groups = [s for s in curves if s.split("|")[0] == kind]
        # By the representative's size, as the paper orders its curves.
        groups.sort(key=lambda s: next(m[1] for m in curves[s].values() if m[0]))
        for n, signature in enumerate(groups):
            colour = colours(n % 10)
            for representative, leaves, points in curves[signature].values():
                phi, f = zip(*points)
                if representative:
                    ax.plot(phi, f, color=colour, lw=2.2, zorder=3,
                            label=f"{signature.split('|', 1)[1]} ({leaves} leaves, "
                                  f"{len(curves[signature])} drawn)")
                else:
                    ax.plot(phi, f, color=colour, lw=0.6, alpha=0.6)
        ax.set_title(f"{kind}: f(θin = φin = 90°, θout = 90°, φout), {args.band}")
        ax.set_xlabel("φout (degrees, structure frame)")
        ax.set_ylabel("f per unit leaf area (1/sr)")
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 45))
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    fig.suptitle("Phase function slices within and across signatures (thick: representative, "
                 "thin: other members)", fontsize=10)
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
