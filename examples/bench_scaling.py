#!/usr/bin/env python3
"""Time and peak memory against scene size: generated trees of 1k, 10k and 100k leaves,
each solver at one setting, a fresh process per run (peak memory is the process's).

Usage: bench_scaling.py BUILD_DIR OUT_DIR [--leaves 1000,10000,100000] [--epsilon 1e-5]
Writes OUT_DIR/scaling.csv and prints the table with the fitted growth exponents.
"""
import argparse
import csv
import math
import os

from summary import generate_tree, solve


def slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build")
    parser.add_argument("out")
    parser.add_argument("--leaves", default="1000,10000,100000")
    parser.add_argument("--epsilon", default="1e-5")
    parser.add_argument("--samples", default="256")
    args = parser.parse_args()
    leaflux = os.path.join(args.build, "server", "leaflux")
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for leaves in [int(n) for n in args.leaves.split(",")]:
        scene = generate_tree(leaflux, args.out, leaves)
        for solver, options in (("hrc", ["--epsilon", args.epsilon]), ("mc", ["--samples", args.samples])):
            row = solve(leaflux, scene, os.path.join(args.out, f"tree{leaves}_{solver}.csv"),
                        ["--solver", solver] + options)
            row.pop("residual_pct")
            rows.append(dict(leaves=leaves, solver=solver, setting=options[1], **row))
    with open(os.path.join(args.out, "scaling.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"{'leaves':>8} {'solver':<6} {'setting':<8} {'wall_s':>8} {'cpu_s':>8} {'peak_MiB':>9} {'links':>9} {'elements':>9}")
    for r in rows:
        print(f"{r['leaves']:>8} {r['solver']:<6} {r['setting']:<8} {r['wall_s']:>8.2f} {r['cpu_s']:>8.2f} "
              f"{r['peak_mib']:>9} {r['links']:>9} {r['elements']:>9}")
    for solver in ("hrc", "mc"):
        points = [r for r in rows if r["solver"] == solver]
        if len(points) > 1:
            print(f"{solver}: time grows as n^{slope([p['leaves'] for p in points], [p['wall_s'] for p in points]):.2f}, "
                  f"peak memory as n^{slope([p['leaves'] for p in points], [p['peak_mib'] for p in points]):.2f}")


if __name__ == "__main__":
    main()
