"""What every part of the evaluation (bench_report.py and the modules beside it) shares: where
the report's files are kept, how a figure is written, and running a benchmark of tests/."""
import csv
import math
import os
import shutil
import subprocess

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
REPORT = os.path.join(HERE, "report")


def number(value, digits=3):
    v = float(value)
    if math.isnan(v):  # not measured (the balance of a reference solved for a sample)
        return "–"
    if v == 0:
        return "0"
    return f"{v:,.0f}" if abs(v) >= 100 else f"{v:.{digits}g}"


def median(values):
    ordered = sorted(values)
    return 0.5 * (ordered[(len(ordered) - 1) // 2] + ordered[len(ordered) // 2])


def bench_rows(build, out, program, name, run, args=()):
    """Runs tests/PROGRAM writing OUT/NAME (when `run`), keeps a copy in examples/report/ and
    returns its rows."""
    if run:
        os.makedirs(out, exist_ok=True)
        subprocess.run([os.path.join(build, "tests", program), os.path.join(out, name), *args], check=True)
        shutil.copy(os.path.join(out, name), os.path.join(REPORT, name))
    return list(csv.DictReader(open(os.path.join(REPORT, name))))
