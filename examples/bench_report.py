#!/usr/bin/python3
"""The evaluation behind docs/results.md and the README's summary table.

Error against run time on the benchmark scenes (`leaflux bench error`), time and memory against size (bench_scaling.py), the growth of
the demo, and the spread of phase functions within a signature (leaflux_bench_phase_spread).
Copies CSVs and plots to examples/report/, then writes each table from those CSVs
between its `<!-- report:NAME -->` and `<!-- /report:NAME -->` markers, so that the docs say
what the last run measured and nothing else: docs/results.md holds every table (one section
per scene), README.md one summary of the error tables (`report:summary`) and HRC's accuracy
on the stiff scenes of tests/hrc_accuracy_test.cpp (`report:accuracy`).

Usage: bench_report.py BUILD_DIR OUT_DIR [--only error,problems,scaling,phase,phase-db,phase-spread,growth,import,accuracy,stability,daemon,
                       daemon-accuracy,soak,rays,render,summary]
                      [--scenes a,b]
                      [--scaling-solvers hrc,mc,instanced,instanced-compact,instanced-tau]
       bench_report.py --tables-only [--only ...]   # rewrite from examples/report/, run nothing
The growth part reads the demo's out/demo/ (run scripts/demo.sh first).
"""
import argparse
import csv
import math
import os
import re
import shutil
import subprocess
import sys

from report_suites import accuracy_section, stability_section

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
REPORT = os.path.join(HERE, "report")
RESULTS = os.path.join(ROOT, "docs", "results.md")
DAEMON_RESULTS = os.path.join(ROOT, "docs", "results_daemon.md")  # the ray engine and daemon
README = os.path.join(ROOT, "README.md")

# name: (how to make the scene, what it is, bench error options)
SCENES = {
    "tree1k": (["--leaves", "1000", "--seed", "2", "--sky-cones", "turtle46"],
               "generated tree, 1,000 leaves, sun + 46-cone overcast sky",
               ["--reference-samples", "8192", "--hrc-epsilon", "1e-3,1e-4,1e-5,1e-6"]),
    "tree10k": (["--leaves", "10000", "--seed", "2", "--sky-cones", "turtle46"],
                "generated tree, 10,000 leaves, sun + 46-cone overcast sky",
                ["--reference-samples", "8192", "--hrc-epsilon", "1e-2,1e-3,1e-4,5e-5,1e-5,1e-6",
                 "--instanced-epsilon", "1e-2,1e-3,1e-4,1e-5", "--instanced-depth", "2,3",
                 "--instanced-merge", "4096"]),
    "tree119k": (["--leaves", "44500", "--seed", "2", "--sky-cones", "turtle46"],
                 "generated tree of 119k triangles (44,500 leaves and their internodes), "
                 "sun + 46-cone overcast sky",
                 ["--reference-samples", "4096", "--hrc-epsilon", "1e-2,1e-3,1e-4,1e-5",
                  "--instanced-epsilon", "1e-2,1e-3,1e-4,1e-5", "--instanced-depth", "3,4",
                  "--instanced-merge", "4096"]),
    "canopy": (["--random-canopy", "--canopy-leaves", "2000", "--lai", "5", "--canopy-width", "2",
                "--seed", "3", "--sky-cones", "turtle46"],
               "dense random canopy, 2,000 leaves, LAI 5, NIR ρ = τ = 0.45, sun + 46-cone sky",
               ["--reference-samples", "8192", "--hrc-epsilon", "1e-3,1e-4,1e-5"]),
    "canopy500": (["--random-canopy", "--canopy-leaves", "500", "--lai", "3", "--canopy-width", "2",
                   "--no-sky"],
                  "random canopy, 500 leaves, LAI 3, NIR ρ = τ = 0.45, sun only (HRC's goal: "
                  "1 % L2 in NIR in 0.3 s)",
                  # The goal's scene: a reference of 16,384 paths would add 0.45 % of noise.
                  ["--reference-samples", "65536", "--hrc-epsilon", "1e-3,3e-4,2e-4,1e-4,1e-5"]),
    "bac1": (None, "Caribu's seedling tray bac1.can (2,270 triangles) under the 46-direction "
                   "overcast sky of Turtle46soc.light",
             ["--reference-samples", "16384", "--hrc-epsilon", "1e-3,1e-4,1e-5"]),
    "plantation": (["--leaves", "1000", "--seed", "2", "--rows", "15", "--columns", "16", "--trees", "233",
                    "--sky-cones", "turtle46"],
                   "plantation of 233 generated trees of 1,000 leaves (the scaling runs' with the "
                   "46-cone sky), sun + 46-cone overcast sky; the reference and every error over "
                   "the leaves of 5 of its trees, spread evenly through it (`--sample-plants 5`), "
                   "every solver solving all of it",
                   ["--reference-samples", "8192", "--sample-plants", "5", "--mc-samples", "256",
                    "--hrc-epsilon", "1e-4,1e-5", "--instanced-epsilon", "1e-4,1e-5,3e-6"]),
    "greenhouse": (["--greenhouse", "--rows", "3", "--columns", "8", "--spacing", "0.8",
                    "--row-spacing", "1.4", "--leaves", "200", "--leaf-length", "0.06"],
                   "greenhouse at night: 24 plants of 200 leaves, white floor and walls, "
                   "three lamp bars, no roof",
                   ["--reference-samples", "4096", "--hrc-epsilon", "1e-3,1e-4,1e-5,1e-6,3e-7",
                    "--instanced-epsilon", "1e-3,1e-4,1e-5"]),
}


def replace_section(path, text, name, body):
    begin, end = f"<!-- report:{name} -->", f"<!-- /report:{name} -->"
    pattern = re.compile(re.escape(begin) + ".*?" + re.escape(end), re.S)
    if not pattern.search(text):
        sys.exit(f"{os.path.relpath(path, ROOT)} has no {begin} … {end} section")
    return pattern.sub(lambda _: f"{begin}\n{body.strip()}\n{end}", text)


def update(path, name, body):
    """Rewrites one section of `path`; the file is read just before, so edits made meanwhile
    stay."""
    text = replace_section(path, open(path).read(), name, body)
    open(path, "w").write(text)


def figure(path, name):
    """A plot of examples/report/ as linked from the file `path`."""
    return os.path.relpath(os.path.join(REPORT, name), os.path.dirname(path))


def number(value, digits=3):
    v = float(value)
    if math.isnan(v):  # not measured (the balance of a reference solved for a sample)
        return "–"
    if v == 0:
        return "0"
    return f"{v:,.0f}" if abs(v) >= 100 else f"{v:.{digits}g}"


def error_section(build, out, name, run=True):
    """Runs `leaflux bench error` on one scene and copies its CSV and plot to examples/report/
    (unless not `run`: they are there); returns its table for docs/results.md."""
    leaflux = os.path.join(build, "server", "leaflux")
    make, description, options = SCENES[name]
    if run:
        scene = os.path.join(HERE, "scenes", f"{name}.scene.txtpb")
        if make is not None:
            scene = os.path.join(out, f"{name}.scene.txtpb")
            subprocess.run([leaflux, "generate", *make, "--out", scene], check=True, capture_output=True)
        subprocess.run([leaflux, "bench", "error", "--scene", scene, "--name", name, "--out", out,
                        "--cache", os.path.join(out, "cache"), *options], check=True)
        for ext in ("csv", "png"):
            shutil.copy(os.path.join(out, f"{name}.{ext}"), os.path.join(REPORT, f"error_{name}.{ext}"))
    rows = error_rows(name)
    per = " / ".join(dict.fromkeys(r["band"] for r in rows))
    table = [f"### {name}", "", f"{description[0].upper()}{description[1:]}; {int(rows[0]['leaves']):,} leaves.", "",
             f"![{name}]({figure(RESULTS, f'error_{name}.png')})", "",
             f"| solver | setting | wall s | cpu s | peak MiB | L2 % of max, {per} | mean rel. %, {per} | "
             f"p95 rel. %, {per} | balance %, {per} |", "|---|---|---|---|---|---|---|---|---|"]
    for key in dict.fromkeys((r["solver"], r["setting"]) for r in rows):
        by_band = [r for r in rows if (r["solver"], r["setting"]) == key]
        first = by_band[0]
        joined = lambda column: " / ".join(number(r[column]) for r in by_band)
        if key[1].startswith("reference"):  # its own error is its standard error
            errors = f"floor {joined('reference_floor_pct')} | – | –"
        else:
            errors = f"{joined('l2_pct_of_max')} | {joined('mean_rel_pct')} | {joined('p95_rel_pct')}"
        table.append(f"| {key[0]} | {key[1]} | {number(first['wall_s'])} | {number(first['cpu_s'])} | "
                     f"{number(first['peak_mib'])} | {errors} | {joined('balance_residual_pct')} |")
    return "\n".join(table)


def error_rows(name):
    return list(csv.DictReader(open(os.path.join(REPORT, f"error_{name}.csv"))))


# The README's summary: these settings of each scene's error table (the instanced solver's
# from the database its first run filled).
SUMMARY = [("mc", "samples", 1024, "Monte Carlo, 1,024 paths"), ("hrc", "epsilon", 1e-4, "HRC, ε = 1e-4"),
           ("hrc", "epsilon", 1e-5, "HRC, ε = 1e-5"), ("instanced", "epsilon", 1e-4, "instanced, ε = 1e-4")]


# The README's rows: the plantation's errors are over a sample of its trees, and its table
# in docs/results.md says so.
SUMMARY_SCENES = [name for name in SCENES if name != "plantation"]


def summary_section(names):
    """One row per scene of docs/results.md's error tables: L2 error, wall time and peak
    memory of a few settings, for the README."""
    table = ["| scene | leaves | " + " | ".join(f"{label}: L2 % PAR / NIR, wall s, MiB" for *_, label in SUMMARY)
             + " |", "|---|---|" + "---|" * len(SUMMARY)]
    for name in names:
        rows = error_rows(name)
        cells = []
        for solver, key, value, _ in SUMMARY:
            # The setting alone ("epsilon=0.0001"), not its variants ("epsilon=0.0001 single-value").
            hit = [r for r in rows if r["solver"] == solver and " " not in r["setting"]
                   and r["setting"].startswith(key + "=") and float(r["setting"].split("=")[1]) == value]
            cells.append(" / ".join(number(r["l2_pct_of_max"]) for r in hit)
                         + f", {number(hit[0]['wall_s'])} s, {number(hit[0]['peak_mib'])}" if hit else "–")
        table.append(f"| [{name}](docs/results.md#{name}) | {int(rows[0]['leaves']):,} | " + " | ".join(cells) + " |")
    return "\n".join(table)


def scaling_section(build, out, solvers, run=True):
    if run:
        subprocess.run([sys.executable, os.path.join(HERE, "bench_scaling.py"), build, out, "--solvers", solvers],
                       check=True)
        for name in ("scaling.csv", "scaling.png", "fits.csv"):
            shutil.copy(os.path.join(out, name), os.path.join(REPORT, name))
    rows = list(csv.DictReader(open(os.path.join(REPORT, "scaling.csv"))))
    table = [f"![scaling]({figure(RESULTS, 'scaling.png')})", "",
             "| series | leaves | trees | solver | setting | wall s | peak MiB | working MiB | links |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        working = (number(float(r["solving_mib"]) - float(r["loaded_mib"]))
                   if r.get("solving_mib") and r["status"] == "ok" else "–")
        figures = (f"{number(r['wall_s'])} | {number(r['peak_mib'])} | {working} | {r['links'] or '–'}"
                   if r["status"] == "ok" else f"{r['status']} | | | ")
        table.append(f"| {r['series']} | {int(r['leaves']):,} | {r['trees']} | {r['solver']} | {r['setting']} | "
                     f"{figures} |")
    fits = list(csv.DictReader(open(os.path.join(REPORT, "fits.csv"))))
    table += ["", "Fitted growth (time ∝ n^a, peak memory ∝ n^b, working memory ∝ n^c): " + "; ".join(
        f"{f['solver']} on {f['series']}: a = {f['time_exponent']}, b = {f['memory_exponent']}"
        + (f", c = {f['working_memory_exponent']}" if f.get("working_memory_exponent") else "") for f in fits) + "."]
    table += ["", largest_scenes(rows)]
    return "\n".join(table)


def largest_scenes(rows):
    """The largest scene of each series, solver by solver, and which runs met the paper's
    goal for the plantation (Soler 2003 §7: ≤ 2 minutes and ≤ 300 MB in all)."""
    goal_mib = 300e6 / 2**20
    text = []
    for series in dict.fromkeys(r["series"] for r in rows):
        ran = [r for r in rows if r["series"] == series and r["status"] == "ok"]
        if not ran:
            continue
        largest = max(int(r["leaves"]) for r in ran)
        at = [r for r in ran if int(r["leaves"]) == largest]
        runs = "; ".join(
            f"{r['solver']} {number(r['wall_s'])} s, {number(r['peak_mib'])} MiB"
            + (f" ({number(float(r['solving_mib']) - float(r['loaded_mib']))} working)"
               if r.get("solving_mib") else "") for r in at)
        scene = (f"{int(at[0]['trees'])} trees, {largest:,} leaves" if series == "trees"
                 else f"One tree of {largest:,} leaves")
        line = f"{scene}: {runs}."
        if series == "trees":
            met = [r["solver"] for r in at if float(r["wall_s"]) <= 120 and float(r["peak_mib"]) <= goal_mib]
            line += (f" The paper's goal for such a plantation, ≤ 2 minutes and ≤ 300 MB "
                     f"({goal_mib:.0f} MiB) in all: met by {', '.join(met) if met else 'none'}.")
        text.append(line)
    return "\n\n".join(text)


# The demo's files copied to examples/report/: (in out/demo/, in examples/report/).
DEMO_FILES = [("growth_comparison.csv", "growth_comparison.csv"), ("growth_comparison.png", "growth_comparison.png"),
              ("cycles.csv", "demo_cycles_full.csv"), ("direct_only/cycles.csv", "demo_cycles_direct_only.csv"),
              ("plants.csv", "demo_plants_full.csv"), ("direct_only/plants.csv", "demo_plants_direct_only.csv"),
              ("growth.png", "demo_growth.png"),
              ("instancing_comparison.csv", "instancing_comparison.csv"),
              ("instancing_comparison.png", "instancing_comparison.png"),
              ("instancing_every_comparison.csv", "instancing_every_comparison.csv"),
              ("instanced/cycles.csv", "demo_cycles_instanced.csv"),
              *[(f"cycle{c}.png", f"demo_cycle{c}.png") for c in (2, 9, 13, 17, 25)],
              ("instanced_every/cycles.csv", "demo_cycles_instanced_every.csv")]


def growth_section(demo, run=True):
    if run:
        for source, target in DEMO_FILES:
            if not os.path.exists(os.path.join(demo, source)):
                sys.exit(f"{os.path.join(demo, source)} missing: run scripts/demo.sh first")
            shutil.copy(os.path.join(demo, source), os.path.join(REPORT, target))
    rows = list(csv.DictReader(open(os.path.join(REPORT, "growth_comparison.csv"))))
    table = [f"![growth comparison]({figure(RESULTS, 'growth_comparison.png')})", "",
             "| cycle | phytomers | structural distance % | leaf distance % | solve s full / direct | "
             "daemon peak MiB full / direct |", "|---|---|---|---|---|---|"]
    for r in rows:
        if int(r["cycle"]) % 5 == 0:
            table.append(f"| {r['cycle']} | {r['phytomers_full']} | {r['structural_distance_pct']} | "
                         f"{r['leaf_distance_pct']} | {number(r['solve_s_full'])} / "
                         f"{number(r['solve_s_direct_only'])} | {number(r['daemon_peak_mib_full'])} / "
                         f"{number(r['daemon_peak_mib_direct_only'])} |")
    return "\n".join(table)


def instancing_section():
    """The demo's plant grown with HRC against the one grown with instancing (the default
    policy: structures of more than 10 leaves, paper Fig. 15's blue curve), and with
    instancing of every structure (its red curve), every 5 cycles."""
    default = list(csv.DictReader(open(os.path.join(REPORT, "instancing_comparison.csv"))))
    every = {r["cycle"]: r for r in csv.DictReader(open(os.path.join(REPORT, "instancing_every_comparison.csv")))}
    runs = {run: {r["cycle"]: r for r in csv.DictReader(open(os.path.join(REPORT, f"demo_cycles_{run}.csv")))}
            for run in ("instanced", "instanced_every")}
    table = [f"![instancing comparison]({figure(RESULTS, 'instancing_comparison.png')})", "",
             "| cycle | phytomers | distance % to HRC: instanced / every structure | per phytomer, max / σ %: "
             "instanced / every structure | solve s HRC / instanced / every structure | phase functions computed "
             "so far: instanced / every structure |", "|---|---|---|---|---|---|"]
    computed = {run: 0 for run in runs}
    for r in default:
        c = r["cycle"]
        for run in runs:
            computed[run] += int(runs[run][c]["phase_computed"])
        if int(c) % 5 == 0:
            a = every[c]
            table.append(f"| {c} | {r['phytomers_hrc']} | {r['structural_distance_pct']} / "
                         f"{a['structural_distance_pct']} | {number(r['phytomer_distance_max_pct'])} / "
                         f"{number(r['phytomer_distance_sd_pct'])}, {number(a['phytomer_distance_max_pct'])} / "
                         f"{number(a['phytomer_distance_sd_pct'])} | {number(r['solve_s_hrc'])} / "
                         f"{number(r['solve_s_instanced'])} / {number(a['solve_s_instanced_every_structure'])} | "
                         f"{computed['instanced']} / {computed['instanced_every']} |")
    return "\n".join(table)


def bench_rows(build, out, program, name, run, args=()):
    """Runs tests/PROGRAM writing OUT/NAME (when `run`), keeps a copy in examples/report/ and
    returns its rows."""
    if run:
        os.makedirs(out, exist_ok=True)
        subprocess.run([os.path.join(build, "tests", program), os.path.join(out, name), *args], check=True)
        shutil.copy(os.path.join(out, name), os.path.join(REPORT, name))
    return list(csv.DictReader(open(os.path.join(REPORT, name))))


def daemon_section(build, out, run=True):
    """Runs leaflux_bench_daemon: the median solve of a cycle of the growing plants, by solver,
    database, start of the iteration and ε, also at the coarsest ε within DAEMON_GOAL_PCT
    of each solver (daemon_coarsest: the daemon-accuracy part runs first)."""
    coarsest = daemon_coarsest()
    growths = sorted({(leaves, e) for (leaves, _), e in coarsest.items()}, key=lambda g: (g[0], float(g[1])))
    rows = bench_rows(build, out, "leaflux_bench_daemon", "daemon_bench.csv", run,
                      [f"{leaves}:{e}" for leaves, e in growths])
    names = {"growing_tree": "HRC", "growing_tree_warm_start": "HRC, warm start",
             "instanced_cold": "instanced, empty database",
             "instanced_warm": "instanced, the database filled",
             "instanced_warm_start": "instanced, the database filled, warm start",
             "instanced_merged": f"instanced, the database filled, merged below {DAEMON_MERGE:,} triangles"}
    table = ["| solver | leaves | ε | median solve ms (10 cycles) | last cycle ms | sweeps (10 cycles) | "
             "phase functions computed |", "|---|---|---|---|---|---|---|"]
    keys = []
    for r in rows:
        key = (r["what"], r["leaves"], r["epsilon"])
        if r["what"] in names and key not in keys:
            keys.append(key)
    for what, leaves, epsilon in sorted(keys, key=lambda k: (int(k[1]), float(k[2]), list(names).index(k[0]))):
        cycle = [r for r in rows if (r["what"], r["leaves"], r["epsilon"]) == (what, leaves, epsilon)]
        solve = median(float(r["solve_ms"]) for r in cycle)
        table.append(f"| {names[what]} | {int(leaves):,} | {float(epsilon):.0e} | {number(solve)} | "
                     f"{number(cycle[-1]['solve_ms'])} | {sum(int(r['iterations']) for r in cycle)} | "
                     f"{sum(int(r['phase_computed']) for r in cycle)} |")
    # The median cycle of each solver at its coarsest ε within the goal.
    sessions = {"HRC": "growing_tree", "instanced": "instanced_warm", "instanced, merged": "instanced_merged"}
    summary = []
    for _, leaves in DAEMON_TREES:
        cells = []
        for label, what in sessions.items():
            e = coarsest.get((leaves, label))
            cycle = [float(r["solve_ms"]) for r in rows if r["what"] == what and int(r["leaves"]) == leaves
                     and e is not None and float(r["epsilon"]) == float(e)]
            if cycle:
                cells.append(f"{label} {number(median(cycle))} ms at ε = {e}")
        summary.append(f"{leaves:,} leaves: " + ", ".join(cells))
    table += ["", f"The median cycle at the coarsest ε within {DAEMON_GOAL_PCT:g} % L2 in every band "
              "(the instanced sessions on the database filled): " + "; ".join(summary) + ".", ""]

    def ratios(what, against, column="solve_ms", statistic=median):
        """By plant: the range over ε of `what`'s statistic of `column` over `against`'s."""
        by = {}
        for leaves, epsilon in {(int(r["leaves"]), r["epsilon"]) for r in rows if r["what"] == what}:
            of = lambda w: statistic([float(r[column]) for r in rows if r["what"] == w and
                                      int(r["leaves"]) == leaves and r["epsilon"] == epsilon])
            by.setdefault(leaves, []).append(of(what) / of(against))
        return " and ".join(f"{number(min(v))}–{number(max(v))} times for {leaves:,} leaves"
                            for leaves, v in sorted(by.items()))
    table.append("Over the ε above, against HRC's at the same ε, the instanced solver's median cycle from "
                 f"a filled database takes {ratios('instanced_warm', 'growing_tree')}. Against the unmerged "
                 f"one's, the merged takes {ratios('instanced_merged', 'instanced_warm')}. Against a start "
                 "from the direct light, the warm start takes "
                 f"{ratios('instanced_warm_start', 'instanced_warm', 'iterations', sum)} the sweeps over the "
                 f"ten cycles, and {ratios('instanced_warm_start', 'instanced_warm')} the median cycle.")
    return "\n".join(table)


def median(values):
    ordered = sorted(values)
    return 0.5 * (ordered[(len(ordered) - 1) // 2] + ordered[len(ordered) // 2])


def spread(values, unit=""):
    """`low–high (median)` of a few runs' values."""
    low, high = min(values), max(values)
    if number(low) == number(high):
        return f"{number(low)}{unit}"
    return f"{number(low)}–{number(high)} ({number(median(values))}){unit}"


def daemon_protocol_section():
    """The protocol's own cost, from leaflux_bench_daemon's CSV (run by daemon_section): a
    Status round trip and a cycle of the grown plant with nothing changed."""
    rows = list(csv.DictReader(open(os.path.join(REPORT, "daemon_bench.csv"))))
    status = next(r for r in rows if r["what"] == "status")
    table = [f"A Status round trip takes {number(status['round_trip_ms'])} ms (mean of many). A cycle with an "
             "empty delta asking the last cycle's outputs sends its light again unsolved; asking no outputs, "
             "as the last did, it is the protocol alone (both medians of 200); asking other outputs, it is "
             "solved again:", "",
             "| leaves | ε | organs in the reply | outputs sent again: round trip ms | the protocol alone ms | "
             "solved again: round trip / solving ms |", "|---|---|---|---|---|---|"]
    at = {(r["what"], r["leaves"], r["epsilon"]): r for r in rows}
    for what, leaves, epsilon in at:
        if what != "empty_delta":
            continue
        again, alone = at[(what, leaves, epsilon)], at[("empty_nothing", leaves, epsilon)]
        solved = at[("empty_resolve", leaves, epsilon)]
        table.append(f"| {int(leaves):,} | {float(epsilon):.0e} | {int(again['organs']):,} | "
                     f"{number(again['round_trip_ms'])} | {number(alone['round_trip_ms'])} | "
                     f"{number(solved['round_trip_ms'])} / {number(solved['solve_ms'])} |")
    return "\n".join(table)


def rays_section(build, out, run=True):
    """Runs leaflux_bench_raytrace (Google Benchmark, three repetitions) and
    leaflux_bench_reference: rays per second of the ray engine, and the Monte Carlo paths a
    10,000-leaf tree needs for 1 % standard error."""
    if run:
        os.makedirs(out, exist_ok=True)
        raytrace = os.path.join(out, "raytrace.csv")
        subprocess.run([os.path.join(build, "tests", "leaflux_bench_raytrace"), "--benchmark_repetitions=3",
                        f"--benchmark_out={raytrace}", "--benchmark_out_format=csv"], check=True)
        shutil.copy(raytrace, os.path.join(REPORT, "raytrace.csv"))
    bench_rows(build, out, "leaflux_bench_reference", "reference_bench.csv", run)
    with open(os.path.join(REPORT, "raytrace.csv")) as f:  # the header follows Google Benchmark's context lines
        lines = f.read().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("name,"))
    runs = list(csv.DictReader(lines[start:]))
    what = {"occlusion_from_bounds": "occlusion, rays from random points of the bounds in random directions",
            "closest_hit_from_bounds": "closest hit, the same rays",
            "occlusion_from_surfaces": "occlusion, rays leaving random triangles (what the solvers shoot)",
            "closest_hit_from_surfaces": "closest hit, the same rays"}
    triangles = next(float(r["triangles"]) for r in runs if r["triangles"])
    table = [f"Ray engine on a generated tree of 10⁵ leaves ({triangles:,.0f} triangles), both cores, "
             "three runs:", "", "| rays | M rays/s: range (median) | hit fraction |", "|---|---|---|"]
    for name, label in what.items():
        # The repetitions ("NAME/min_time:2.000/real_time"), not their aggregates ("…_mean").
        at = [r for r in runs if r["name"].split("/")[0] == name and r["name"].endswith("real_time")]
        table.append(f"| {label} | {spread([float(r['rays_per_s']) / 1e6 for r in at])} | "
                     f"{number(median(float(r['hit_fraction']) for r in at))} |")
    reference = list(csv.DictReader(open(os.path.join(REPORT, "reference_bench.csv"))))
    table += ["", "Monte Carlo on a 10,000-leaf tree, NIR (ρ = τ = 0.45), sun + CIE overcast sky: the paths "
              "per leaf that reach a median relative standard error of 1 % over lit leaves (the first run "
              "aims, the second checks):", "",
              "| paths per leaf | wall s | cpu s | median relative standard error % | lit leaves | rays | peak MiB |",
              "|---|---|---|---|---|---|---|"]
    for r in reference:
        table.append(f"| {int(r['samples_per_leaf']):,} | {number(r['wall_s'])} | {number(r['cpu_s'])} | "
                     f"{100 * float(r['median_rel_stderr']):.2f} | {int(r['lit_leaves']):,} | "
                     f"{int(r['rays']):,} | {number(r['peak_rss_mib'])} |")
    return "\n".join(table)


# The daemon's growing trees as scenes (no ground, 46-cone sky: ε relative to the plant's own
# light) and the ε their cycles' accuracy is measured at: (name, leaves).
DAEMON_TREES = [("tree1k_bare", 1000), ("tree10k_bare", 10000)]
DAEMON_EPSILONS = ["1e-4", "2e-4", "3e-4", "5e-4", "7e-4", "1e-3", "2e-3", "3e-3", "5e-3", "7e-3", "1e-2", "2e-2",
                   "5e-2", "1e-1"]
DAEMON_GOAL_PCT = 2.0  # the L2 error a cycle is asked to stay within, per band
DAEMON_MERGE = 4096  # leaflux_bench_daemon's kMergeTriangles: the "merged" sessions' bound
# The daemon's sessions by solver, as `leaflux bench error` names the same solves: label,
# solver and what follows the ε in the run's setting.
DAEMON_SOLVERS = {"HRC": ("hrc", []), "instanced": ("instanced", []),
                  "instanced, merged": ("instanced", [f"merge-triangles={DAEMON_MERGE}"])}


def daemon_accuracy_rows(name):
    """The daemon-accuracy CSV of one tree: {(solver label, ε): [its rows, one per band]}."""
    at = {}
    for r in csv.DictReader(open(os.path.join(REPORT, f"daemon_accuracy_{name}.csv"))):
        setting = r["setting"].split()
        if not setting or not setting[0].startswith("epsilon="):
            continue
        epsilon = float(setting[0].split("=")[1])
        for label, (solver, rest) in DAEMON_SOLVERS.items():
            for e in DAEMON_EPSILONS:
                if r["solver"] == solver and setting[1:] == rest and float(e) == epsilon:
                    at.setdefault((label, e), []).append(r)
    return at


def daemon_coarsest():
    """The coarsest ε of DAEMON_EPSILONS whose solve stays within DAEMON_GOAL_PCT in every
    band, by tree and solver: {(leaves, solver label): ε}, from the daemon-accuracy CSVs."""
    coarsest = {}
    for name, leaves in DAEMON_TREES:
        at = daemon_accuracy_rows(name)
        within = [(label, e) for (label, e), rows in at.items()
                  if all(float(r["l2_pct_of_max"]) <= DAEMON_GOAL_PCT for r in rows)]
        for label, e in within:
            if float(e) > float(coarsest.get((leaves, label), 0)):
                coarsest[(leaves, label)] = e
    return coarsest


def daemon_accuracy_section(build, out, run=True):
    """`leaflux bench error` on the daemon's trees at the ε of its cycles, HRC and the
    instanced solver (from the database its cold run filled), also merged: how much accuracy
    each ε costs, and the coarsest ε within DAEMON_GOAL_PCT in every band."""
    leaflux = os.path.join(build, "server", "leaflux")
    table = ["| ε | " + " | ".join(f"{leaves:,} leaves, {label}" for _, leaves in DAEMON_TREES
                                   for label in DAEMON_SOLVERS) + " |",
             "|---|" + "---|" * (len(DAEMON_TREES) * len(DAEMON_SOLVERS))]
    accuracy = {}
    for name, leaves in DAEMON_TREES:
        if run:
            os.makedirs(out, exist_ok=True)
            scene = os.path.join(out, f"{name}.scene.txtpb")
            subprocess.run([leaflux, "generate", "--leaves", str(leaves), "--no-ground", "--sky-cones", "turtle46",
                            "--out", scene], check=True, capture_output=True)
            subprocess.run([leaflux, "bench", "error", "--scene", scene, "--name", name, "--out", out,
                            "--cache", os.path.join(out, "cache"), "--no-mc", "--no-direct", "--no-plot",
                            "--hrc-epsilon", ",".join(DAEMON_EPSILONS),
                            "--instanced-epsilon", ",".join(DAEMON_EPSILONS),
                            "--instanced-merge", str(DAEMON_MERGE)], check=True)
            shutil.copy(os.path.join(out, f"{name}.csv"), os.path.join(REPORT, f"daemon_accuracy_{name}.csv"))
        accuracy[leaves] = daemon_accuracy_rows(name)
    for epsilon in DAEMON_EPSILONS:
        cells = []
        for _, leaves in DAEMON_TREES:
            for label in DAEMON_SOLVERS:
                rows = accuracy[leaves].get((label, epsilon))
                cells.append(" / ".join(number(r["l2_pct_of_max"]) for r in rows) if rows else "–")
        table.append(f"| {epsilon} | " + " | ".join(cells) + " |")
    coarsest = daemon_coarsest()
    found = [f"{leaves:,} leaves, {label}: {coarsest.get((leaves, label), 'none of these')}"
             for _, leaves in DAEMON_TREES for label in DAEMON_SOLVERS]
    table += ["", f"The coarsest ε whose solve stays within {DAEMON_GOAL_PCT:g} % L2 in every band: "
              + "; ".join(found) + ". The daemon's cycles are timed at these ε too (the table above)."]
    return "\n".join(table)


def soak_section(build, out, run=True):
    """Runs tests/daemon_soak.py (also in the test suite): many clients cycling and churning
    sessions on one daemon; its throughput, latency and resident memory."""
    name = "daemon_soak.csv"
    if run:
        os.makedirs(out, exist_ok=True)
        subprocess.run([sys.executable, os.path.join(ROOT, "tests", "daemon_soak.py"), "--leafluxd",
                        os.path.join(build, "server", "leafluxd"), "--csv", os.path.join(out, name)], check=True)
        shutil.copy(os.path.join(out, name), os.path.join(REPORT, name))
    r = next(csv.DictReader(open(os.path.join(REPORT, name))))
    mib = lambda column: f"{int(r[column]) / 1024:.1f} MiB"
    return (f"{int(r['clients'])} clients, {int(r['cycles']):,} cycles in {number(r['seconds'])} s: "
            f"{number(r['cycles_per_s'])} cycles/s, latency p50 {number(r['p50_ms'])} ms and p99 "
            f"{number(r['p99_ms'])} ms; resident memory {mib('rss_before_kb')} after the warm-up and "
            f"{mib('rss_after_kb')} at the end (the test fails above +{mib('rss_bound_kb')}).")


def render_sections(build, out, run=True):
    """Runs bench_render.py: pictures of the 119k tree by HRC and by instancing, a plantation
    (in false and true colour) and the greenhouse, each drawn from its solve's CSV at 1024 × 768; returns the time
    table for docs/results.md and the pictures for the README."""
    if run:
        subprocess.run([sys.executable, os.path.join(HERE, "bench_render.py"), build, out], check=True)
        for name in ("render.csv", "render_culling.csv"):
            shutil.copy(os.path.join(out, name), os.path.join(REPORT, name))
    rows = list(csv.DictReader(open(os.path.join(REPORT, "render.csv"))))
    if run:
        for r in rows:
            shutil.copy(os.path.join(out, r["png"]), os.path.join(REPORT, r["png"]))
    table = ["| picture | size | rays a pixel | rays | render s | M rays/s | colour scale W/m² |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        table.append(f"| {r['picture']} | {r['size']} | {r['pixel_samples']} | {int(r['rays']):,} | "
                     f"{number(r['render_s'])} | {number(int(r['rays']) / float(r['render_s']) / 1e6)} | "
                     f"0–{number(r['scale_max'])} |")
    by = {r["picture"]: r for r in rows}
    link = lambda name: figure(README, by[name]["png"])
    pictures = ["| the 119k tree lit by HRC | the same by the instanced solver, one scale |", "|---|---|",
                f"| ![HRC]({link('tree119k_hrc')}) | ![instanced]({link('tree119k_instanced')}) |", "",
                "| a plantation of 16 trees | the same in true colour (its R, G, B bands) | "
                "inside the greenhouse at night |", "|---|---|---|",
                f"| ![plantation]({link('plantation_hrc')}) | ![true colour]({link('plantation_colour')}) | "
                f"![greenhouse]({link('greenhouse_hrc')}) |"]
    return "\n".join(table), "\n".join(pictures + wall_hole_series()), culling_table()


def culling_table():
    """The instanced solver opening only the instances in view (render --open-in-view)
    against opening them all (render_culling.csv), for docs/results.md."""
    path = os.path.join(REPORT, "render_culling.csv")
    if not os.path.exists(path):
        return "(run `bench_report.py --only render`)"
    table = ["| view | instances | opened, all | opened, in view | solve s, all | solve s, in view | "
             "peak MiB, all | peak MiB, in view | mean difference W/m² | pixels apart by > 1 grey level |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in csv.DictReader(open(path)):
        table.append(f"| {r['view']} | {int(r['instances']):,} | {int(r['opened_all']):,} | "
                     f"{int(r['opened_in_view']):,} | {number(r['solve_s_all'])} | {number(r['solve_s_in_view'])} | "
                     f"{number(r['peak_mib_all'])} | {number(r['peak_mib_in_view'])} | "
                     f"{number(r['mean_abs_wm2'])} | {number(r['pixels_apart_pct'])} % |")
    return "\n".join(table)


def wall_hole_series():
    """The demo's wall-hole plant at cycles 2, 9, 13, 17 and 25 (copied by the growth part),
    for the README's pictures: a table row of five, or nothing before the demo ran."""
    cycles = [c for c in (2, 9, 13, 17, 25) if os.path.exists(os.path.join(REPORT, f"demo_cycle{c}.png"))]
    if not cycles:
        return []
    return ["", "| " + " | ".join(f"wall-hole, cycle {c}" for c in cycles) + " |", "|---" * len(cycles) + "|",
            "| " + " | ".join(f"![cycle {c}]({figure(README, f'demo_cycle{c}.png')})" for c in cycles) + " |"]


def demo_section():
    """The demo's two plants at their first and last cycles (cycles.csv and plants.csv of
    each run; the wall-hole scenario has one plant)."""
    table = [f"![growth]({figure(RESULTS, 'demo_growth.png')})", "",
             "| light | cycle | leaves | leaf area m² | biomass g | PAR absorbed W | leaf-area centroid x m | "
             "solve s | daemon peak MiB |", "|---|---|---|---|---|---|---|---|---|"]
    for label, run in (("full", "full"), ("direct only", "direct_only")):
        rows = list(csv.DictReader(open(os.path.join(REPORT, f"demo_cycles_{run}.csv"))))
        plants = {p["cycle"]: p for p in csv.DictReader(open(os.path.join(REPORT, f"demo_plants_{run}.csv")))}
        for r in (rows[0], rows[-1]):
            table.append(f"| {label} | {r['cycle']} | {r['leaves']} | {number(r['leaf_area_m2'], 4)} | "
                         f"{number(r['biomass_g'], 4)} | {number(r['absorbed_par_w'], 4)} | "
                         f"{float(plants[r['cycle']]['centroid_x']):.2f} | {number(r['solve_s'])} | "
                         f"{number(r['daemon_peak_mib'])} |")
    return "\n".join(table)


def phase_sections(build, out, run=True):
    """Runs leaflux_bench_phase: the paper's §4.2.2 table on a generated branch and the time
    to compute a structure's functions; returns the two tables."""
    if run:
        os.makedirs(out, exist_ok=True)
        subprocess.run([os.path.join(build, "tests", "leaflux_bench_phase"), out], check=True)
        for name in ("phase_table.csv", "phase_functions.csv"):
            shutil.copy(os.path.join(out, name), os.path.join(REPORT, name))
    rows = list(csv.DictReader(open(os.path.join(REPORT, "phase_table.csv"))))
    table = ["| function | method | L∞ % | L2 % | size kB | seconds |", "|---|---|---|---|---|---|"]
    for r in rows:
        table.append(f"| {r['function']} | {r['method']} | {float(r['linf_pct']):.1f} | "
                     f"{float(r['l2_pct']):.2f} | {number(r['kB'])} | {number(r['seconds'])} |")
    rows = list(csv.DictReader(open(os.path.join(REPORT, "phase_functions.csv"))))
    times = ["| leaves | triangles | function | directions | rays | seconds | kB |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        times.append(f"| {r['leaves']} | {r['triangles']} | {r['function']} | {r['directions']} | "
                     f"{int(r['rays']):,} | {number(r['seconds'])} | {number(r['kB'])} |")
    return "\n".join(table), "\n".join(times)


def problems_section(build, out, run=True):
    """The instanced solver's local problems on the 119k tree at ε = 1e-4 (the paper's
    Fig. 14, right): `leaflux solve --problems`, a histogram of their sizes, and a table
    by depth."""
    csv_path = os.path.join(REPORT, "problems_tree119k.csv")
    if run:
        leaflux = os.path.join(build, "server", "leaflux")
        scene = os.path.join(out, "error", "tree119k.scene.txtpb")
        if not os.path.exists(scene):
            subprocess.run([leaflux, "generate", *SCENES["tree119k"][0], "--out", scene], check=True,
                           capture_output=True)
        database = os.path.join(out, "problems_phase.db")
        for _ in range(2):  # the second from the database the first filled
            subprocess.run([leaflux, "solve", "--scene", scene, "--solver", "instanced", "--epsilon", "1e-4",
                            "--phase-db", database, "--out", os.path.join(out, "problems_leaves.csv"),
                            "--problems", csv_path, "--quiet"], check=True, capture_output=True)
    rows = list(csv.DictReader(open(csv_path)))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        figure_, axis = plt.subplots(figsize=(6, 3.5))
        sizes = [int(r["elements"]) for r in rows]
        bins = [2 ** k for k in range(0, max(sizes).bit_length() + 1)]
        axis.hist(sizes, bins=bins)
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.set_xlabel("elements of a local problem")
        axis.set_ylabel("problems")
        axis.set_title("tree119k, instanced, ε = 1e-4")
        figure_.tight_layout()
        figure_.savefig(os.path.join(REPORT, "problems_tree119k.png"), dpi=110)
    except ImportError:
        print("no matplotlib: no histogram", file=sys.stderr)
    table = [f"![local problems]({figure(RESULTS, 'problems_tree119k.png')})", "",
             "| depth | problems | triangles (mean) | closed instances (mean) | elements (mean) | "
             "links (mean) | seconds (sum, both threads) |", "|---|---|---|---|---|---|---|"]
    for depth in sorted({int(r["depth"]) for r in rows}):
        at = [r for r in rows if int(r["depth"]) == depth]
        mean = lambda column: number(sum(float(r[column]) for r in at) / len(at))
        table.append(f"| {depth} | {len(at):,} | {mean('triangles')} | {mean('closed')} | {mean('elements')} | "
                     f"{mean('links')} | {number(sum(float(r['seconds']) for r in at))} |")
    return "\n".join(table)


def phase_db_section(build, out, run=True):
    """Runs leaflux_bench_phase_db: the database's miss, hit and load times and its size on
    disk against the number of functions it holds."""
    rows = bench_rows(build, out, "leaflux_bench_phase_db", "phase_db.csv", run)
    table = ["| function | functions | blob kB | miss + store ms | memory hit µs | disk hit ms | "
             "file MB | compacted MB |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        kind = "bi 130² × 2 bands" if r["kind"] == "bi" else "mono 130 × 2 bands"
        table.append(f"| {kind} | {int(r['functions']):,} | {number(int(r['blob_bytes']) / 1000)} | "
                     f"{number(r['miss_store_ms'])} | {number(r['memory_hit_us'])} | "
                     f"{number(r['disk_hit_ms'])} | {number(r['file_mb'])} | {number(r['compacted_mb'])} |")
    return "\n".join(table)


def import_section(build, out, run=True, largest="1000000"):
    """Runs leaflux_bench_import: the importers' read time on OBJ, .can and OPF files of
    10⁴–10⁶ triangles it generates, and on an OPF the size of a measured plant."""
    if run:
        os.makedirs(out, exist_ok=True)
        subprocess.run([os.path.join(build, "tests", "leaflux_bench_import"),
                        os.path.join(out, "import.csv"), largest], check=True)
        shutil.copy(os.path.join(out, "import.csv"), os.path.join(REPORT, "import.csv"))
    rows = list(csv.DictReader(open(os.path.join(REPORT, "import.csv"))))
    names = {"obj": "OBJ", "can": "Caribu .can", "opf": "OPF (shared meshes)",
             "opf-plant": "OPF, a measured plant's size", "opf-plant-z":
             "OPF, the same with zero-length internodes and NaN diameters"}
    table = ["| file | triangles | organs | skipped | file MB | read s | MB/s | M triangles/s |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        table.append(f"| {names.get(r['format'], r['format'])} | {int(r['triangles']):,} | "
                     f"{int(r['organs']):,} | {int(r['skipped']):,} | {number(r['file_mb'])} | "
                     f"{number(r['read_s'])} | {number(r['mb_per_s'])} | "
                     f"{number(r['mtriangles_per_s'])} |")
    return "\n".join(table)


def phase_spread_section(build, out, run=True):
    """Runs leaflux_bench_phase_spread (the fitted policy on four generated trees) and plots
    its Fig. 8 slices into examples/report/; returns the NIR table for docs/results.md."""
    if run:
        os.makedirs(out, exist_ok=True)
        subprocess.run([os.path.join(build, "tests", "leaflux_bench_phase_spread"), out], check=True)  # minutes
        for name in ("phase_spread.csv", "phase_slices.csv"):
            shutil.copy(os.path.join(out, name), os.path.join(REPORT, name))
        subprocess.run([sys.executable, os.path.join(HERE, "plot_phase_spread.py"),
                        os.path.join(REPORT, "phase_slices.csv"), os.path.join(REPORT, "phase_slices.png")],
                       check=True)
    rows = [r for r in csv.DictReader(open(os.path.join(REPORT, "phase_spread.csv"))) if r["band"] == "NIR"]
    table = [f"![phase slices]({figure(RESULTS, 'phase_slices.png')})", "",
             "| signature | members solved / in group | leaves | τ spread % (noise) | f spread % | f rep. error % | "
             "f/leaf area rep. error % | scattered rep. error % | intercepted rep. error % (noise) | nearest other group | "
             "f error with its rep. % | f/leaf area error with its rep. % |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    cell = lambda signature: signature.replace("|", "\\|")  # a signature's parts are split by |
    for r in rows:
        other = (f"{cell(r['nearest_other'])} | {number(r['f_other_error_pct'])} | "
                 f"{number(r['f_shape_other_error_pct'])}" if r["nearest_other"] else "– | – | –")
        leaves = (f"{int(r['min_leaves']):,}" if r["min_leaves"] == r["max_leaves"]
                  else f"{int(r['min_leaves']):,}–{int(r['max_leaves']):,}")
        table.append(f"| {cell(r['signature'])} | {r['sampled']} / {int(r['members']):,} | {leaves} | "
                     f"{number(r['tau_spread_pct'])} ({number(r['tau_noise_pct'])}) | {number(r['f_spread_pct'])} | {number(r['f_rep_error_pct'])} | "
                     f"{number(r['f_shape_rep_error_pct'])} | {number(r['scattered_rep_error_pct'])} | "
                     f"{number(r['intercepted_rep_error_pct'])} ({number(r['intercepted_noise_pct'])}) | {other} |")
    return "\n".join(table)

def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build", nargs="?", default=os.path.join(ROOT, "build", "release"),
                        help="build directory (default: build/release)")
    parser.add_argument("out", nargs="?", default=os.path.join(ROOT, "out", "report"),
                        help="directory of the runs' files (default: out/report)")
    parser.add_argument("--only", default="error,problems,scaling,phase,phase-db,phase-spread,growth,import,accuracy,stability,daemon,daemon-accuracy,soak,rays,render",
                        help="parts to run (default: all)")
    parser.add_argument("--scenes", default=",".join(SCENES), help="error part: scenes (default: all)")
    parser.add_argument("--scaling-solvers", default="hrc,mc,instanced,instanced-compact,instanced-tau",
                        help="solvers the scaling run measures; the others' rows are kept from OUT_DIR")
    parser.add_argument("--demo", default=os.path.join(ROOT, "out", "demo"),
                        help="growth part: the output of scripts/demo.sh (default: out/demo)")
    parser.add_argument("--import-largest", default="1000000",
                        help="import: the largest files' triangle count (default: %(default)s)")
    parser.add_argument("--tables-only", action="store_true",
                        help="rewrite the tables from the CSVs in examples/report/, run nothing")
    args = parser.parse_args()
    build, out = os.path.abspath(args.build), os.path.abspath(args.out)
    run = not args.tables_only
    os.makedirs(REPORT, exist_ok=True)
    parts = args.only.split(",")
    if "summary" in parts and "error" not in parts:
        update(README, "summary", summary_section(SUMMARY_SCENES))
    if "error" in parts:
        os.makedirs(os.path.join(out, "error"), exist_ok=True)
        for name in args.scenes.split(","):
            # Each table is written as soon as it is measured.
            update(RESULTS, f"error-{name}", error_section(build, os.path.join(out, "error"), name, run))
        update(README, "summary", summary_section(SUMMARY_SCENES))
    if "problems" in parts:
        update(RESULTS, "problems", problems_section(build, out, run))
    if "scaling" in parts:
        update(RESULTS, "scaling", scaling_section(build, os.path.join(out, "scaling"), args.scaling_solvers, run))
    if "phase" in parts:
        table, times = phase_sections(build, os.path.join(out, "phase"), run)
        update(RESULTS, "phase-table", table)
        update(RESULTS, "phase-functions", times)
    if "growth" in parts:
        update(RESULTS, "growth", growth_section(args.demo, run))
        if "render" not in parts and os.path.exists(os.path.join(REPORT, "render.csv")):
            update(README, "pictures", render_sections(build, out, run=False)[1])  # the new series
        update(RESULTS, "demo", demo_section())
        update(RESULTS, "growth-instanced", instancing_section())
    if "daemon-accuracy" in parts:  # first: the daemon's cycles are timed at the ε it finds
        update(DAEMON_RESULTS, "daemon-accuracy",
               daemon_accuracy_section(build, os.path.join(out, "daemon_accuracy"), run))
    if "daemon" in parts:
        update(DAEMON_RESULTS, "daemon", daemon_section(build, os.path.join(out, "daemon"), run))
        update(DAEMON_RESULTS, "daemon-protocol", daemon_protocol_section())
    if "soak" in parts:
        update(DAEMON_RESULTS, "soak", soak_section(build, os.path.join(out, "soak"), run))
    if "render" in parts:
        table, pictures, culling = render_sections(build, os.path.join(out, "render"), run)
        update(RESULTS, "render", table)
        update(RESULTS, "render-culling", culling)
        update(README, "pictures", pictures)
    if "rays" in parts:
        update(DAEMON_RESULTS, "rays", rays_section(build, os.path.join(out, "rays"), run))
    if "phase-db" in parts:
        update(RESULTS, "phase-db", phase_db_section(build, os.path.join(out, "phase"), run))
    if "phase-spread" in parts:
        update(RESULTS, "phase-spread", phase_spread_section(build, os.path.join(out, "phase_spread"), run))
    if "import" in parts:
        update(RESULTS, "import", import_section(build, os.path.join(out, "import"), run,
                                                 args.import_largest))
    if "accuracy" in parts:
        update(README, "accuracy", accuracy_section(build, os.path.join(out, "accuracy"), run))
    if "stability" in parts:
        update(RESULTS, "stability", stability_section(build, os.path.join(out, "stability"), run))
    print(f"sections {args.only} rewritten in docs/results.md or docs/results_daemon.md"
          f"{' and the summary in README.md' if 'error' in parts or 'summary' in parts else ''}; files in {REPORT}")


if __name__ == "__main__":
    main()
