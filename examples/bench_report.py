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

from report_common import HERE, REPORT, ROOT, bench_rows, median, number
from report_daemon import daemon_accuracy_section, daemon_protocol_section, daemon_section, soak_section
from report_suites import accuracy_section, stability_section

RESULTS = os.path.join(ROOT, "docs", "results.md")
DAEMON_RESULTS = os.path.join(ROOT, "docs", "results_daemon.md")  # the ray engine and daemon
PHASE_RESULTS = os.path.join(ROOT, "docs", "results_phase.md")  # phase functions
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
    "copies": (["--leaves", "8000", "--seed", "2", "--rows", "15", "--columns", "16", "--trees", "233",
                "--copies", "--prototypes", "4", "--instanced", "--sky-cones", "turtle46"],
               "the paper's plantation (Soler 2003 Fig. 16): 233 generated trees of 8,000 leaves, "
               "about 5 M polygons, copies of 4 prototype trees written as an instanced scene, sun + "
               "46-cone overcast sky; the reference and every error over the leaves of 5 of its "
               "trees (`--sample-plants 5`), the instanced solver solving all of it (HRC needed "
               "13 GiB for 10⁶ leaves and Monte Carlo 23 minutes: neither runs here)",
               ["--max-nodes", "6000000", "--reference-samples", "4096", "--sample-plants", "5",
                "--no-mc", "--no-hrc", "--no-direct", "--instanced-epsilon", "1e-3"]),
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
             f"| solver | setting | wall s | cpu s | peak MiB | working MiB | L2 % of max, {per} | "
             f"mean rel. %, {per} | p95 rel. %, {per} | balance %, {per} |", "|---|---|---|---|---|---|---|---|---|---|"]
    for key in dict.fromkeys((r["solver"], r["setting"]) for r in rows):
        by_band = [r for r in rows if (r["solver"], r["setting"]) == key]
        first = by_band[0]
        joined = lambda column: " / ".join(number(r[column]) for r in by_band)
        if key[1].startswith("reference"):  # its own error is its standard error
            errors = f"floor {joined('reference_floor_pct')} | – | –"
        else:
            errors = f"{joined('l2_pct_of_max')} | {joined('mean_rel_pct')} | {joined('p95_rel_pct')}"
        table.append(f"| {key[0]} | {key[1]} | {number(first['wall_s'])} | {number(first['cpu_s'])} | "
                     f"{number(first['peak_mib'])} | {number(first['working_mib']) if first.get('working_mib') else '–'} | "
                     f"{errors} | {joined('balance_residual_pct')} |")
    return "\n".join(table)


def error_rows(name):
    return list(csv.DictReader(open(os.path.join(REPORT, f"error_{name}.csv"))))


# The README's summary: these settings of each scene's error table (the instanced solver's
# from the database its first run filled).
SUMMARY = [("mc", "samples", 1024, "Monte Carlo, 1,024 paths"), ("hrc", "epsilon", 1e-4, "HRC, ε = 1e-4"),
           ("hrc", "epsilon", 1e-5, "HRC, ε = 1e-5"), ("instanced", "epsilon", 1e-4, "instanced, ε = 1e-4")]


# The README's rows: the plantation's errors are over a sample of its trees, and its table
# in docs/results.md says so.
SUMMARY_SCENES = [name for name in SCENES if name not in ("plantation", "copies")]


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
    goal for its plantation of 233 trees and about 5 M polygons (Soler 2003 §7, Fig. 16: ≤ 2
    minutes and ≤ 300 MB in all), the plantation of copies."""
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
        trees = int(at[0]["trees"])
        scene = {"one tree": f"One tree of {largest:,} leaves",
                 "trees": f"{trees} trees, {largest:,} leaves",
                 "copies": f"{trees} copies of 4 trees, {largest:,} leaves"}[series]
        line = f"{scene}: {runs}."
        if series == "copies":
            # In all: the process's time, reading the scene included; a run without it is
            # not judged.
            whole = {r["solver"]: float(r["process_s"]) for r in at if r.get("process_s")}
            line += " In all, reading the scene included: " + "; ".join(
                f"{r['solver']} {number(whole[r['solver']])} s (the scene once read: "
                f"{number(r['loaded_mib'])} MiB)" for r in at if r["solver"] in whole) + "."
            fast = {r["solver"] for r in at if whole.get(r["solver"], math.inf) <= 120}
            lean = {r["solver"] for r in at if r["solver"] in whole and float(r["peak_mib"]) <= goal_mib}
            by = lambda solvers: ", ".join(r["solver"] for r in at if r["solver"] in solvers) or "none"
            line += (f" The paper's goal for its plantation (233 trees, about 5 M polygons), ≤ 2 "
                     f"minutes and ≤ 300 MB ({goal_mib:.0f} MiB) in all: met by {by(fast & lean)}; "
                     f"the time by {by(fast)}, the memory by {by(lean)}.")
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


def spread(values, unit=""):
    """`low–high (median)` of a few runs' values."""
    low, high = min(values), max(values)
    if number(low) == number(high):
        return f"{number(low)}{unit}"
    return f"{number(low)}–{number(high)} ({number(median(values))}){unit}"


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
    table = [f"![phase slices]({figure(PHASE_RESULTS, 'phase_slices.png')})", "",
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
        update(PHASE_RESULTS, "phase-table", table)
        update(PHASE_RESULTS, "phase-functions", times)
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
        update(PHASE_RESULTS, "phase-db", phase_db_section(build, os.path.join(out, "phase"), run))
    if "phase-spread" in parts:
        update(PHASE_RESULTS, "phase-spread", phase_spread_section(build, os.path.join(out, "phase_spread"), run))
    if "import" in parts:
        update(RESULTS, "import", import_section(build, os.path.join(out, "import"), run,
                                                 args.import_largest))
    if "accuracy" in parts:
        update(README, "accuracy", accuracy_section(build, os.path.join(out, "accuracy"), run))
    if "stability" in parts:
        update(RESULTS, "stability", stability_section(build, os.path.join(out, "stability"), run))
    print(f"sections {args.only} rewritten in docs/results.md, results_daemon.md or results_phase.md"
          f"{' and the summary in README.md' if 'error' in parts or 'summary' in parts else ''}; files in {REPORT}")


if __name__ == "__main__":
    main()
