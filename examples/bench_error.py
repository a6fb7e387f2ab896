#!/usr/bin/env python3
"""Error against run time: lights generated trees with the Monte Carlo reference at a high
sample count, then with each solver at several settings, and writes for each run the wall
time, CPU time, peak memory, the L2 error in % of the reference maximum (Soler 2003,
Fig. 14) and the mean and 95th-percentile relative errors over lit leaves, per band.

Usage: bench_error.py BUILD_DIR OUT_DIR [--leaves 1000,10000] [--quick]
Writes OUT_DIR/error.csv and OUT_DIR/error.png and prints the table.
"""
import argparse
import csv
import os
import sys

from compare import errors, load
from summary import generate_tree, solve

def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build")
    parser.add_argument("out")
    parser.add_argument("--leaves", default="1000,10000")
    parser.add_argument("--reference-samples", type=int, default=8192)
    args = parser.parse_args()
    leaflux = os.path.join(args.build, "server", "leaflux")
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for leaves in [int(n) for n in args.leaves.split(",")]:
        # Both solvers see the same 46-cone sky, so the error is the solver's alone.
        scene = generate_tree(leaflux, args.out, leaves, "turtle46")
        reference = os.path.join(args.out, f"tree{leaves}_reference.csv")
        if not os.path.exists(reference):  # the reference is cached: delete it to redo it
            solve(leaflux, scene, reference,
                  ["--solver", "mc", "--samples", str(args.reference_samples), "--seed", "99"])
        ref = load(reference)
        settings = [("mc", ["--samples", str(n)], f"samples={n}") for n in (64, 256, 1024)]
        settings += [("hrc", ["--epsilon", e], f"epsilon={e}") for e in ("1e-3", "1e-4", "1e-5", "1e-6")]
        for solver, options, label in settings:
            out = os.path.join(args.out, f"tree{leaves}_{solver}_{label}.csv")
            run = solve(leaflux, scene, out, ["--solver", solver] + options)
            wall, cpu, peak, residual = run["wall_s"], run["cpu_s"], run["peak_mib"], run["residual_pct"]
            value = load(out)
            for band in ("PAR", "NIR"):
                l2, mean, p95 = errors(ref, value, band)
                rows.append(dict(scene=f"tree{leaves}", leaves=leaves, solver=solver, setting=label, band=band,
                                 wall_s=wall, cpu_s=cpu, peak_mib=peak, l2_pct_of_max=round(l2, 3),
                                 mean_rel_pct=round(mean, 3), p95_rel_pct=round(p95, 3),
                                 balance_residual_pct=residual.get(band, float("nan"))))
    with open(os.path.join(args.out, "error.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"{'scene':<10} {'solver':<4} {'setting':<14} {'band':<4} {'wall_s':>7} {'peak_MiB':>8} "
          f"{'L2_%max':>8} {'mean_rel%':>9} {'p95_rel%':>8} {'balance%':>8}")
    for r in rows:
        print(f"{r['scene']:<10} {r['solver']:<4} {r['setting']:<14} {r['band']:<4} {r['wall_s']:>7.2f} "
              f"{r['peak_mib']:>8.0f} {r['l2_pct_of_max']:>8.2f} {r['mean_rel_pct']:>9.2f} "
              f"{r['p95_rel_pct']:>8.2f} {r['balance_residual_pct']:>8.2f}")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plot", file=sys.stderr)
        return
    scenes = sorted({r["scene"] for r in rows}, key=lambda s: int(s[4:]))
    fig, axes = plt.subplots(1, len(scenes) * 2, figsize=(6 * len(scenes) * 2, 4.5), squeeze=False)
    for i, (scene, band) in enumerate((s, b) for s in scenes for b in ("PAR", "NIR")):
        ax = axes[0][i]
        for solver, marker in (("mc", "o"), ("hrc", "s")):
            points = [r for r in rows if r["scene"] == scene and r["band"] == band and r["solver"] == solver]
            ax.loglog([p["wall_s"] for p in points], [p["l2_pct_of_max"] for p in points], marker=marker,
                      label=solver)
            for p in points:
                ax.annotate(p["setting"].split("=")[1], (p["wall_s"], p["l2_pct_of_max"]), fontsize=7)
        ax.set_title(f"{scene} {band}")
        ax.set_xlabel("wall time (s, 2 cores)")
        ax.set_ylabel("L2 error (% of max)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "error.png"), dpi=100)
    print(f"wrote {os.path.join(args.out, 'error.csv')} and error.png")


if __name__ == "__main__":
    main()
