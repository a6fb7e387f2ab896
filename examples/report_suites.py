"""The parts of the evaluation that are test suites run for their figures (bench_report.py
--only stability,accuracy): each test records what it measured in gtest's JSON output, and
the section writes the figures of the last run beside what they are held to."""
import csv
import json
import os
import subprocess

REPORT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "report")


# The stability suite's tests by scene, in the table's order: (test name, what it is).
STABILITY = [
    ("DenseCanopyConservesEnergy", "dense canopy (120 leaves, LAI 4, grey ground), ρ + τ = {scatter}"),
    ("ClosedBoxAbsorbsAllTheLampEmits", "closed box lit by a lamp, ρ = {scatter}, at ε = 1e-6"),
    ("LeavesOneMicrometreApart", "two leaves 1 µm apart"),
    ("IntersectingLeaves", "intersecting leaves"),
    ("LampOneMillimetreBelowALeaf", "a lamp 1 mm under a leaf"),
    ("SunHalfADegreeAboveTheHorizon", "sun 0.5° above the horizon on a vertical leaf"),
    ("ReflectanceEqualToTransmittance", "a canopy with ρ = τ"),
    ("SunExactlyAtADirectionSetVertex", "sun exactly on a direction-set vertex"),
    ("CoordinatesOffsetAHundredKilometres", "coordinates offset by 10⁵ m"),
    ("LeavesOfOneMillimetreAndTenMetres", "leaves of 1 mm and 10 m"),
    ("TheBrightestSunAcceptedGivesFiniteLight", "the brightest sun accepted"),
    ("OneLeaf", "one leaf"),
    ("BlackLeavesAbsorbEverything", "black leaves"),
]


def gtest_records(build, out, pattern, name):
    """Runs the tests `pattern` selects and yields each test's record in gtest's JSON output
    (its name, failures and the properties it recorded), kept as OUT/NAME.json."""
    os.makedirs(out, exist_ok=True)
    json_path = os.path.join(out, f"{name}.json")
    subprocess.run([os.path.join(build, "tests", "leaflux_tests"), f"--gtest_filter={pattern}",
                    f"--gtest_output=json:{json_path}"], check=True, capture_output=True)
    for suite in json.load(open(json_path))["testsuites"]:
        yield from suite["testsuite"]


def stability_section(build, out, run=True):
    """The stability suite (tests/stability_test.cpp) for every solver: the sweeps,
    extrapolation jumps and energy balance each run records (gtest's JSON output)."""
    csv_path = os.path.join(REPORT, "stability.csv")
    if run:
        rows = []
        for test in gtest_records(build, out, "*Stability*", "stability"):
            if "balance_residual" not in test:
                continue
            name, solver = test["name"].split("/")
            scatter = ""
            if "_scatter" in solver:
                solver, scatter = solver.split("_scatter")
                scatter = f"{float('0.' + scatter):g}"
            rows.append({"test": name, "solver": solver, "scatter": scatter,
                         "iterations": test["iterations"], "extrapolations": test["extrapolations"],
                         "balance_pct": 100 * float(test["balance_residual"]),
                         "balance_stderr_pct": 100 * float(test["balance_stderr"]),
                         "passed": "failures" not in test})
        with open(csv_path, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    rows = list(csv.DictReader(open(csv_path)))
    solvers = [s for s in ("hrc", "instanced", "mc") if any(r["solver"] == s for r in rows)]
    names = {"hrc": "HRC (ε = 1e-5)", "instanced": "instanced (ε = 1e-5)", "mc": "Monte Carlo (1,024 paths)"}
    table = ["| scene | " + " | ".join(f"{names[s]}: sweeps (jumps), balance ± s.e. %" for s in solvers) + " |",
             "|---" * (len(solvers) + 1) + "|"]
    for test, what in STABILITY:
        for scatter in dict.fromkeys(r["scatter"] for r in rows if r["test"] == test):
            cells = []
            for solver in solvers:
                at = [r for r in rows if (r["test"], r["solver"], r["scatter"]) == (test, solver, scatter)]
                if not at:
                    cells.append("–")
                    continue
                r = at[0]
                sweeps = "" if solver == "mc" else f"{r['iterations']} ({r['extrapolations']}), "
                mark = "" if r["passed"] == "True" else " **failed**"
                cells.append(f"{sweeps}{float(r['balance_pct']):+.2f} ± {float(r['balance_stderr_pct']):.2f}{mark}")
            table.append(f"| {what.format(scatter=scatter)} | " + " | ".join(cells) + " |")
    return "\n".join(table)


def accuracy_section(build, out, run=True):
    """HRC where users work (tests/hrc_accuracy_test.cpp): the figures each property's test
    records (gtest's JSON output), against the goals they are held to."""
    csv_path = os.path.join(REPORT, "hrc_accuracy.csv")
    if run:
        rows = []
        for test in gtest_records(build, out, "HrcAccuracy.*", "hrc_accuracy"):
            for key, value in test.items():
                if key not in ("name", "file", "line", "status", "result", "timestamp", "time",
                               "classname", "failures"):
                    rows.append({"test": test["name"], "figure": key, "value": float(value),
                                 "passed": "failures" not in test})
        with open(csv_path, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    values = {r["figure"]: float(r["value"]) for r in csv.DictReader(open(csv_path))}
    failed = {r["test"] for r in csv.DictReader(open(csv_path)) if r["passed"] != "True"}

    def v(key, digits=2):
        return f"{values[key]:.{digits}f}"
    lines = [
        ("SkyConesAreSoftShadowsNotHardBeams",
         "250 leaves (ρ = τ = 0.45) under the 46-cone uniform sky, per side against the continuous sky",
         "≤ 1.5 % at ε = 1e-4",
         f"{v('cones_hrc_1e-4_pct')} % at 1e-4, {v('cones_hrc_1e-5_pct')} % at 1e-5 "
         f"(Monte Carlo on the cones: {v('cones_mc_pct')} %)"),
        ("AConeAcrossALeafLightsBothItsSides",
         "a sun of 0.2 rad across a lone leaf's plane, each side against a grid of its directions",
         "≤ 0.01 % of the normal irradiance", f"{values['across_worst_pct_of_normal']:.1e} %"),
        ("AGroundAroundTheCanopyDoesNotMakeItsLeavesCoarse",
         "150 leaves on a ±10 m and a ±200 m ground, per side against Monte Carlo, ε = 1e-4",
         "the same within noise",
         f"{v('ground_10m_pct')} % and {v('ground_200m_pct')} %"),
        ("AGroundIsSplitForTheLightItSendsTheLeaves",
         "20 leaves over a dark (ρ = 0.1) and a white (ρ = 0.9) ±10 m ground under a sun and the "
         "46-cone sky, per side against Monte Carlo, ε = 1e-4",
         "as accurate (within 1.5 times) with under half the white ground's links",
         f"{v('dark_ground_pct')} % with {values['dark_ground_links']:,.0f} links; "
         f"{v('white_ground_pct')} % with {values['white_ground_links']:,.0f}"),
        ("ALampBarLightsEachLeafSideAsRaysFind",
         "400 leaves 1.3 m under a black lamp bar 5 m long, direct light only, per side against "
         "Monte Carlo, ε = 1e-4",
         "≤ 15 % per side (27 % when the lamp was split first); each side's sum within 2 %",
         f"{v('lamp_side_pct')} %; lower sides {v('lamp_lower_ratio', 3)} of the reference's"),
        ("AnIsotropicFieldLightsEverySideAlikeFromEveryDirection",
         "RAMI's purist corner (ρ + τ = 1, white ±200 m ground, uniform sky): every side 100 W/m², v = 0",
         "‖v‖ ≤ 0.05; worst side ≤ 5 % at 1e-5",
         f"ε = 1e-4: sd {v('isotropic_1e-4_sd_pct')} %, worst {v('isotropic_1e-4_worst_pct', 1)} %, "
         f"‖v‖ ≤ {v('isotropic_1e-4_largest_v', 3)}; 1e-5: sd {v('isotropic_1e-5_sd_pct')} %, "
         f"worst {v('isotropic_1e-5_worst_pct', 1)} %, ‖v‖ ≤ {v('isotropic_1e-5_largest_v', 3)}"),
        ("LightVectorsUnderSunAndSkyFollowTheReference",
         "light vectors under a sun and a cone sky against 65,536 paths a leaf, ε = 1e-4",
         "length within 0.05, direction within 5° where ‖v‖ > 0.2",
         f"{v('vectors_worst_length', 3)}; {v('vectors_worst_deg', 1)}° (p95 {v('vectors_p95_deg', 1)}°)"),
        ("ASunLightsADenseCrownAndTheGroundBeneathAsRaysThroughItFind",
         "eight crowns of 3,000 leaves (LAI 5) under a vertical sun: the disc beneath against the gap "
         "fraction, the leaves against the area they shade, by independent rays",
         "≤ 0.5 % (disc), ≤ 0.2 % (leaves)",
         f"{float(values['crown_disc_pct']):+.2f} %, {float(values['crown_leaves_pct']):+.2f} %"),
    ]
    table = ["| property (test `HrcAccuracy.…`) | goal | HRC |", "|---|---|---|"]
    for test, what, goal, got in lines:
        mark = " **failed**" if test in failed else ""
        table.append(f"| {what} (`{test}`) | {goal} | {got}{mark} |")
    return "\n".join(table)
