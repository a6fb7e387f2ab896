#!/usr/bin/python3
"""Plots a leaflux-grow run (its cycles.csv): leaves, leaf area, biomass and absorbed PAR
per cycle, and the solve time. Usage: plot_growth.py RUN_DIR LABEL [OTHER_RUN_DIR LABEL ...]
Writes RUN_DIR/growth.png."""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def read(run):
    with open(os.path.join(run, "cycles.csv")) as f:
        return list(csv.DictReader(f))


def main(*pairs):
    run = pairs[0]
    runs = list(zip(pairs[0::2], pairs[1::2]))
    columns = [("leaves", "leaves"), ("leaf_area_m2", "leaf area (m²)"), ("biomass_g", "biomass (g)"),
               ("absorbed_par_w", "absorbed PAR (W)"), ("solve_s", "solve time (s)")]
    fig, axes = plt.subplots(1, len(columns), figsize=(4 * len(columns), 3.5))
    for path, label in runs:
        rows = read(path)
        cycles = [int(r["cycle"]) for r in rows]
        for ax, (column, title) in zip(axes, columns):
            ax.plot(cycles, [float(r[column]) for r in rows], marker=".", label=label)
            ax.set_title(title)
            ax.set_xlabel("cycle")
            ax.grid(alpha=0.3)
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(os.path.join(run, "growth.png"), dpi=100)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split()))
    parser.add_argument("runs", nargs="+", metavar="RUN_DIR LABEL",
                        help="a leaflux-grow run's folder and its label, one pair or more")
    args = parser.parse_args()
    if len(args.runs) % 2:
        parser.error("give each run's folder with its label: RUN_DIR LABEL [RUN_DIR LABEL ...]")
    main(*args.runs)
