#!/usr/bin/python3
"""Time and peak memory against scene size, each solver at one setting, a fresh process
per run (peak memory is the process's): one generated tree of 1k to 10⁶ leaves, and
plantations of 1 to 233 trees of 1,000 leaves. Fits the growth exponent of time and
memory per series and solver (paper §3.5: HRC's n·log n time and super-linear memory are
the baseline instantiation must beat).

Usage: bench_scaling.py BUILD_DIR OUT_DIR [--leaves 1000,10000,100000,1000000]
                        [--trees 1,4,16,64,233] [--epsilon 1e-5] [--samples 256]
Writes OUT_DIR/scaling.csv and OUT_DIR/scaling.png and prints the table. A run that fails
(out of memory) is a row with its exit status and no figures.
"""
import argparse
import csv
import math
import os
import subprocess

from summary import generate_tree, solve


def slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def plantation(leaflux, out_dir, trees):
    """`trees` trees of 1,000 leaves, 6 m apart on a square grid; returns the scene path."""
    scene = os.path.join(out_dir, f"trees{trees}.scene.txtpb")
    columns = math.ceil(math.sqrt(trees))
    subprocess.run([leaflux, "generate", "--leaves", "1000", "--seed", "2", "--rows",
                    str(math.ceil(trees / columns)), "--columns", str(columns), "--trees", str(trees),
                    "--out", scene], check=True, capture_output=True)
    return scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build", help="the build folder, with server/leaflux")
    parser.add_argument("out", help="folder of the scenes, scaling.csv, fits.csv and scaling.png "
                        "(made when missing)")
    parser.add_argument("--leaves", default="1000,10000,100000,1000000",
                        help="leaves of each generated tree, comma-separated; empty: none "
                        "(default: %(default)s)")
    parser.add_argument("--trees", default="1,4,16,64,233",
                        help="trees of 1,000 leaves in each plantation, comma-separated; empty: "
                        "none (default: %(default)s)")
    parser.add_argument("--epsilon", default="1e-5", help="HRC's ε (default: %(default)s)")
    parser.add_argument("--samples", default="256",
                        help="Monte Carlo paths per receiver (default: %(default)s)")
    parser.add_argument("--solvers", default="hrc,mc",
                        help="solvers to run; the rows of the others are kept from OUT/scaling.csv "
                        "(default: %(default)s)")
    args = parser.parse_args()
    run_solvers = args.solvers.split(",")
    kept = {}
    previous = os.path.join(args.out, "scaling.csv")
    if os.path.exists(previous):
        for r in csv.DictReader(open(previous)):
            if r["solver"] not in run_solvers:
                for key in ("leaves", "trees", "links", "elements"):
                    r[key] = int(r[key]) if r[key] else ""
                for key in ("wall_s", "cpu_s", "peak_mib"):
                    r[key] = float(r[key]) if r[key] else ""
                kept[(r["series"], r["leaves"], r["solver"])] = r
    leaflux = os.path.join(args.build, "server", "leaflux")
    os.makedirs(args.out, exist_ok=True)
    scenes = [("one tree", int(n), 1, lambda n=int(n): generate_tree(leaflux, args.out, n))
              for n in args.leaves.split(",") if n]
    scenes += [("trees", 1000 * int(t), int(t), lambda t=int(t): plantation(leaflux, args.out, t))
               for t in args.trees.split(",") if t]
    rows = []
    for series, leaves, trees, make in scenes:
        scene = make()
        for solver, options in (("hrc", ["--epsilon", args.epsilon]), ("mc", ["--samples", args.samples])):
            if solver not in run_solvers:
                if (series, leaves, solver) in kept:
                    rows.append(kept[(series, leaves, solver)])
                continue
            row = dict(series=series, leaves=leaves, trees=trees, solver=solver, setting=options[1])
            try:
                result = solve(leaflux, scene, os.path.join(args.out, f"{series[0]}{leaves}_{solver}.csv"),
                               ["--solver", solver] + options)
                result.pop("residual_pct")
                row.update(result, status="ok")
            except subprocess.CalledProcessError as e:
                row.update(wall_s="", cpu_s="", peak_mib="", links="", elements="",
                           status=f"failed (exit {e.returncode})")
            rows.append(row)
            print(f"{series:<9} {leaves:>8} {trees:>4} {solver:<4} {row['status']:<16} "
                  f"{row['wall_s']!s:>9} s {row['peak_mib']!s:>7} MiB", flush=True)
    with open(os.path.join(args.out, "scaling.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    fits = []
    for series in dict.fromkeys(r["series"] for r in rows):
        for solver in ("hrc", "mc"):
            points = [r for r in rows if r["series"] == series and r["solver"] == solver and r["status"] == "ok"]
            if len(points) > 1:
                n = [p["leaves"] for p in points]
                fits.append((series, solver, slope(n, [p["wall_s"] for p in points]),
                             slope(n, [p["peak_mib"] for p in points]), min(n), max(n)))
    with open(os.path.join(args.out, "fits.csv"), "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["series", "solver", "time_exponent", "memory_exponent", "from_leaves", "to_leaves"])
        writer.writerows([s, v, round(t, 3), round(m, 3), a, b] for s, v, t, m, a, b in fits)
    for series, solver, t, m, a, b in fits:
        print(f"{series}, {solver}: time grows as n^{t:.2f}, peak memory as n^{m:.2f} ({a:,} to {b:,} leaves)")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for series, style in (("one tree", "-"), ("trees", "--")):
        for solver, marker in (("hrc", "s"), ("mc", "o")):
            points = [r for r in rows if r["series"] == series and r["solver"] == solver and r["status"] == "ok"]
            if not points:
                continue
            label = f"{solver}, {series}"
            for ax, column in zip(axes, ("wall_s", "peak_mib")):
                ax.loglog([p["leaves"] for p in points], [p[column] for p in points], style, marker=marker,
                          label=label)
    for ax, title in zip(axes, ("wall time (s, 2 cores)", "peak memory (MiB)")):
        ax.set_xlabel("leaves")
        ax.set_ylabel(title)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"HRC at ε = {args.epsilon}, Monte Carlo at {args.samples} paths a leaf")
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "scaling.png"), dpi=100)


if __name__ == "__main__":
    main()
