#!/usr/bin/python3
"""Time and peak memory against scene size, each solver at one setting, a fresh process
per run (peak memory is the process's): one generated tree of 1k to 10⁶ leaves,
plantations of 1 to 233 trees of 1,000 leaves, and the paper's plantation (Soler 2003 Fig. 16):
233 trees of 8,000 leaves, about 5 M polygons, copies of 4 prototype trees written as an
instanced scene. Fits the growth exponent of time, peak
memory and working memory (the peak while solving less the memory once the scene is
loaded) per series and solver (paper §3.5: HRC's n·log n time and super-linear memory are
the baseline instantiation must beat). The instanced solver runs at HRC's ε from a phase-function
database in OUT_DIR that an earlier run filled (a run that had to compute a function is
run again), with shadows by geometry (`instanced`, the default), by geometry in the ray
engine's compact hierarchy (`instanced-compact`) and by transmittance (`instanced-tau`,
which never holds the whole scene's triangles).

Usage: bench_scaling.py BUILD_DIR OUT_DIR [--leaves 1000,10000,100000,1000000]
                        [--trees 1,4,16,64,233] [--copies 233] [--copies-leaves 8000]
                        [--epsilon 1e-5] [--samples 256]
                        [--solvers hrc,mc,instanced,instanced-compact,instanced-tau]
                        [--tau-leaves 250000] [--hrc-leaves 1000000] [--mc-leaves 1000000]
Writes OUT_DIR/scaling.csv, OUT_DIR/fits.csv and OUT_DIR/scaling.png and prints the table.
A run that fails (out of memory) is a row with its exit status and no figures.
"""
import argparse
import csv
import math
import os
import subprocess
import time

from summary import generate_tree, solve


def slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


# solver: (args, database) -> (setting, leaflux solve options)
SOLVERS = {
    "hrc": lambda args, db: (args.epsilon, ["--solver", "hrc", "--epsilon", args.epsilon]),
    "mc": lambda args, db: (args.samples, ["--solver", "mc", "--samples", args.samples]),
    "instanced": lambda args, db: (args.epsilon, ["--solver", "instanced", "--epsilon", args.epsilon,
                                                  "--phase-db", db]),
    "instanced-compact": lambda args, db: (args.epsilon, ["--solver", "instanced", "--epsilon", args.epsilon,
                                                          "--phase-db", db, "--shadows", "geometry-compact"]),
    "instanced-tau": lambda args, db: (args.epsilon, ["--solver", "instanced", "--epsilon", args.epsilon,
                                                      "--phase-db", db, "--shadows", "transmittance"]),
}
COLUMNS = ["series", "leaves", "trees", "solver", "setting", "wall_s", "cpu_s", "peak_mib", "loaded_mib",
           "solving_mib", "links", "elements", "process_s", "status"]
SERIES = ("one tree", "trees", "copies")
# The scenes' largest node count: the paper's plantation expands to 4.3 M nodes.
MAX_NODES = "6000000"


def working_mib(row):
    """The solver's working memory: the process's peak while solving less its memory once
    the scene was loaded, at least 1 MiB so that its logarithm is fitted (None where the
    run did not measure it)."""
    measured = row.get("loaded_mib") not in ("", None) and row.get("solving_mib") not in ("", None)
    return max(row["solving_mib"] - row["loaded_mib"], 1) if measured else None


def plantation(leaflux, out_dir, trees):
    """`trees` trees of 1,000 leaves, 6 m apart on a square grid; returns the scene path."""
    scene = os.path.join(out_dir, f"trees{trees}.scene.txtpb")
    columns = math.ceil(math.sqrt(trees))
    subprocess.run([leaflux, "generate", "--leaves", "1000", "--seed", "2", "--rows",
                    str(math.ceil(trees / columns)), "--columns", str(columns), "--trees", str(trees),
                    "--out", scene], check=True, capture_output=True)
    return scene


def copies_plantation(leaflux, out_dir, trees, leaves):
    """`trees` trees of `leaves` leaves, 6 m apart on a square grid, copies of 4 prototype
    trees each turned about z, written instanced (the file grows with the placements, not
    the polygons); returns the scene path."""
    scene = os.path.join(out_dir, f"copies{trees}x{leaves}.scene.binpb")
    columns = math.ceil(math.sqrt(trees))
    subprocess.run([leaflux, "generate", "--leaves", str(leaves), "--seed", "2", "--rows",
                    str(math.ceil(trees / columns)), "--columns", str(columns), "--trees", str(trees),
                    "--copies", "--prototypes", "4", "--instanced", "--out", scene],
                   check=True, capture_output=True)
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
    parser.add_argument("--copies", default="233",
                        help="trees of the plantation of copies (the paper's Fig. 16); empty: none "
                        "(default: %(default)s)")
    parser.add_argument("--copies-leaves", type=int, default=8000,
                        help="leaves of each tree of the plantation of copies: 8,000 makes 233 "
                        "trees about 5 M polygons (default: %(default)s)")
    parser.add_argument("--epsilon", default="1e-5", help="HRC's ε (default: %(default)s)")
    parser.add_argument("--samples", default="256",
                        help="Monte Carlo paths per receiver (default: %(default)s)")
    parser.add_argument("--tau-leaves", type=int, default=250000,
                        help="instanced-tau runs on scenes of at most this many leaves: its "
                        "shadows through every closed instance's τ take several times the "
                        "time of shadows by geometry (default: %(default)s)")
    parser.add_argument("--hrc-leaves", type=int, default=1000000,
                        help="HRC runs on scenes of at most this many leaves: it needed 13 GiB "
                        "for 10⁶ (default: %(default)s)")
    parser.add_argument("--mc-leaves", type=int, default=1000000,
                        help="Monte Carlo runs on scenes of at most this many leaves: it took 23 "
                        "minutes for 10⁶ (default: %(default)s)")
    parser.add_argument("--solvers", default=",".join(SOLVERS),
                        help="solvers to run; the rows of the others, and of the scenes not run, "
                        "are kept from OUT/scaling.csv (default: %(default)s)")
    args = parser.parse_args()
    run_solvers = args.solvers.split(",")
    # The previous run's rows: those of the solvers not run now, and of the scenes not run
    # now, are kept.
    kept = {}
    previous = os.path.join(args.out, "scaling.csv")
    if os.path.exists(previous):
        for r in csv.DictReader(open(previous)):
            for key in ("leaves", "trees", "links", "elements"):
                r[key] = int(r[key]) if r[key] else ""
            for key in ("wall_s", "cpu_s", "peak_mib", "loaded_mib", "solving_mib", "process_s"):
                r[key] = float(r[key]) if r.get(key) else ""
            kept[(r["series"], r["leaves"], r["solver"])] = r
    leaflux = os.path.join(args.build, "server", "leaflux")
    os.makedirs(args.out, exist_ok=True)
    scenes = [("one tree", int(n), 1, lambda n=int(n): generate_tree(leaflux, args.out, n))
              for n in args.leaves.split(",") if n]
    scenes += [("trees", 1000 * int(t), int(t), lambda t=int(t): plantation(leaflux, args.out, t))
               for t in args.trees.split(",") if t]
    scenes += [("copies", args.copies_leaves * int(t), int(t),
                lambda t=int(t): copies_plantation(leaflux, args.out, t, args.copies_leaves))
               for t in args.copies.split(",") if t]
    # solver: (the option bounding its scenes, the most leaves it runs on)
    most_leaves = {"instanced-tau": ("--tau-leaves", args.tau_leaves), "hrc": ("--hrc-leaves", args.hrc_leaves),
                   "mc": ("--mc-leaves", args.mc_leaves)}
    rows = []
    run_scenes = {(series, leaves) for series, leaves, _, _ in scenes}
    rows += [r for (series, leaves, _), r in kept.items() if (series, leaves) not in run_scenes]
    for series, leaves, trees, make in scenes:
        scene = make()
        database = os.path.join(args.out, "phase.db")
        for solver in SOLVERS:
            if solver not in run_solvers:
                if (series, leaves, solver) in kept:
                    rows.append(kept[(series, leaves, solver)])
                continue
            setting, options = SOLVERS[solver](args, database)
            row = dict(series=series, leaves=leaves, trees=trees, solver=solver, setting=setting)
            if solver in most_leaves and leaves > most_leaves[solver][1]:
                row.update(status="not run (over {} {})".format(*most_leaves[solver]))
                rows.append(row)
                continue
            try:
                out = os.path.join(args.out, f"{series[0]}{leaves}_{solver}.csv")
                options = options + ["--max-nodes", MAX_NODES]
                start = time.monotonic()
                result = solve(leaflux, scene, out, options)
                if result.get("phase_computed"):  # its functions are in the database now
                    start = time.monotonic()
                    result = solve(leaflux, scene, out, options)
                result["process_s"] = round(time.monotonic() - start, 2)  # reading the scene too
                result.pop("residual_pct")
                result.pop("phase_computed", None)
                row.update(result, status="ok")
            except subprocess.CalledProcessError as e:
                row.update(wall_s="", cpu_s="", peak_mib="", loaded_mib="", solving_mib="", links="", elements="",
                           process_s="", status=f"failed (exit {e.returncode})")
            rows.append(row)
            print(f"{series:<9} {leaves:>8} {trees:>4} {solver:<4} {row['status']:<16} "
                  f"{row['wall_s']!s:>9} s {row['peak_mib']!s:>7} MiB", flush=True)
    rows.sort(key=lambda r: (SERIES.index(r["series"]), r["leaves"], list(SOLVERS).index(r["solver"])))
    with open(os.path.join(args.out, "scaling.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS, restval="")
        writer.writeheader()
        writer.writerows(rows)
    fits = []
    for series in dict.fromkeys(r["series"] for r in rows):
        for solver in SOLVERS:
            points = [r for r in rows if r["series"] == series and r["solver"] == solver and r["status"] == "ok"]
            if len(points) > 1:
                n = [p["leaves"] for p in points]
                working = [working_mib(p) for p in points]
                fits.append((series, solver, slope(n, [p["wall_s"] for p in points]),
                             slope(n, [p["peak_mib"] for p in points]),
                             slope(n, working) if all(working) else "", min(n), max(n)))
    with open(os.path.join(args.out, "fits.csv"), "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["series", "solver", "time_exponent", "memory_exponent", "working_memory_exponent",
                         "from_leaves", "to_leaves"])
        writer.writerows([s, v, round(t, 3), round(m, 3), round(w, 3) if w != "" else "", a, b]
                         for s, v, t, m, w, a, b in fits)
    for series, solver, t, m, w, a, b in fits:
        working = f", working memory as n^{w:.2f}" if w != "" else ""
        print(f"{series}, {solver}: time grows as n^{t:.2f}, peak memory as n^{m:.2f}{working} "
              f"({a:,} to {b:,} leaves)")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6))
    for series, style in zip(SERIES, ("-", "--", ":")):
        for solver, marker, colour in zip(SOLVERS, ("s", "o", "^", "D", "v"), ("C0", "C1", "C2", "C4", "C3")):
            points = [r for r in rows if r["series"] == series and r["solver"] == solver and r["status"] == "ok"]
            if not points:
                continue
            label = f"{solver}, {series}"
            values = ([p["wall_s"] for p in points], [p["peak_mib"] for p in points],
                      [working_mib(p) for p in points])
            for ax, ys in zip(axes, values):
                if all(ys):
                    ax.loglog([p["leaves"] for p in points], ys, style, marker=marker, color=colour,
                              label=label)
    for ax, title in zip(axes, ("wall time (s, 2 cores)", "peak memory (MiB)",
                                "working memory (MiB)")):
        ax.set_xlabel("leaves")
        ax.set_ylabel(title)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"HRC and instanced at ε = {args.epsilon}, Monte Carlo at {args.samples} paths a leaf; "
                 "working memory: the peak while solving less the loaded scene")
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "scaling.png"), dpi=100)


if __name__ == "__main__":
    main()
