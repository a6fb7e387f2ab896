"""The daemon's parts of the evaluation (bench_report.py --only daemon,daemon-accuracy,soak):
a growth cycle's time by solver, the protocol's own cost, a cycle's accuracy at each ε and
many clients at once, written to docs/results_daemon.md."""
import csv
import os
import shutil
import subprocess
import sys

from report_common import REPORT, ROOT, bench_rows, median, number


def daemon_section(build, out, run=True):
    """Runs leaflux_bench_daemon: the median solve of a cycle of the growing plants, by solver,
    database, start of the iteration and ε, also at the coarsest ε within DAEMON_GOAL_PCT
    of each solver (daemon_coarsest: the daemon-accuracy part runs first)."""
    coarsest = daemon_coarsest()
    growths = sorted({(leaves, e) for (leaves, _), e in coarsest.items()}, key=lambda g: (g[0], float(g[1])))
    rows = bench_rows(build, out, "leaflux_bench_daemon", "daemon_bench.csv", run,
                      [f"--merge-triangles={DAEMON_MERGE}", *(f"{leaves}:{e}" for leaves, e in growths)])
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


# The daemon's growing trees as scenes (no ground, 46-cone sky: ε relative to the plant's own
# light) and the ε their cycles' accuracy is measured at: (name, leaves).
DAEMON_TREES = [("tree1k_bare", 1000), ("tree10k_bare", 10000)]
DAEMON_EPSILONS = ["1e-4", "2e-4", "3e-4", "5e-4", "7e-4", "1e-3", "2e-3", "3e-3", "5e-3", "7e-3", "1e-2", "2e-2",
                   "5e-2", "1e-1"]
DAEMON_GOAL_PCT = 2.0  # the L2 error a cycle is asked to stay within, per band
# The merge bound of the "merged" sessions (leaflux_bench_daemon --merge-triangles): the
# generated trees' branches, of 2,720 triangles on the 10,000-leaf plant, each solved as one
# problem with its twigs.
DAEMON_MERGE = 4096
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
