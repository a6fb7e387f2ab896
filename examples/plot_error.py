#!/usr/bin/python3
"""Plots a `leaflux bench error` CSV: error against wall time (log–log), one panel per band,
one line per solver, the reference's own standard error drawn as a floor.

Usage: plot_error.py ERROR.csv OUT.png
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {"mc": ("o", "tab:blue"), "hrc": ("s", "tab:orange"), "direct": ("^", "tab:red")}


def main():
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("csv", help="the CSV of leaflux bench error")
    parser.add_argument("png", help="the plot to write")
    args = parser.parse_args()
    rows = list(csv.DictReader(open(args.csv)))
    scene = rows[0]["scene"]
    bands = list(dict.fromkeys(r["band"] for r in rows))
    fig, axes = plt.subplots(1, len(bands), figsize=(5.5 * len(bands), 4.2), squeeze=False)
    for ax, band in zip(axes[0], bands):
        runs = [r for r in rows if r["band"] == band and not r["setting"].startswith("reference")]
        reference = [r for r in rows if r["band"] == band and r["setting"].startswith("reference")]
        for solver in dict.fromkeys(r["solver"] for r in runs):
            points = [r for r in runs if r["solver"] == solver]
            marker, color = STYLE.get(solver, ("x", None))
            times = [float(p["wall_s"]) for p in points]
            errors = [max(float(p["l2_pct_of_max"]), 1e-3) for p in points]
            ax.loglog(times, errors, marker=marker, color=color, label=solver)
            for p, t, e in zip(points, times, errors):
                ax.annotate(p["setting"].split("=")[-1], (t, e), fontsize=7,
                            xytext=(3, 3), textcoords="offset points")
        if reference and float(reference[0]["reference_floor_pct"]) > 0:
            floor = float(reference[0]["reference_floor_pct"])
            ax.axhline(floor, color="gray", linestyle="--",
                       label=f"reference's standard error ({reference[0]['setting'].split('=')[-1]} paths,"
                             f" {float(reference[0]['wall_s']):.0f} s)")
        ax.set_title(f"{scene}: {band}, {rows[0]['leaves']} leaves")
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel("L2 error (% of the reference maximum)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.png, dpi=100)
    print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
