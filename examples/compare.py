#!/usr/bin/python3
"""Compares per-leaf results of two solvers: `compare.py REFERENCE.csv OTHER.csv`.
Prints, per band, the L2 error in % of the reference maximum (Soler 2003, Fig. 14), the
mean and 95th-percentile relative errors over lit leaves (5 % of the brightest or more),
and the mean signed error of each fifth of the leaves from the darkest to the brightest
(in % of the maximum): a solver that spreads light too evenly is high in the first fifths
and low in the last."""
import argparse
import csv
import math

LIT = 0.05


def load(path):
    """Leaf irradiance (both sides, W/m²) by (organ, band)."""
    values = {}
    for row in csv.DictReader(open(path)):
        if row["organ"].startswith("leaf"):
            values[(row["organ"], row["band"])] = (float(row["irradiance_upper_wm2"]) +
                                                   float(row["irradiance_lower_wm2"]))
    return values


def errors(reference, value, band):
    """(L2 % of max, mean relative %, 95th-percentile relative %) over one band's leaves."""
    keys = [k for k in reference if k[1] == band]
    largest = max(reference[k] for k in keys)
    l2 = math.sqrt(sum((value[k] - reference[k]) ** 2 for k in keys) / len(keys)) / largest
    relative = sorted(abs(value[k] - reference[k]) / reference[k] for k in keys if reference[k] >= LIT * largest)
    mean = sum(relative) / len(relative)
    p95 = relative[min(len(relative) - 1, int(0.95 * len(relative)))]
    return 100 * l2, 100 * mean, 100 * p95


def bias_by_fifth(reference, value, band):
    """Mean signed error (% of max) of each fifth of the leaves, darkest first."""
    keys = sorted((k for k in reference if k[1] == band), key=lambda k: reference[k])
    largest = reference[keys[-1]]
    fifths = [keys[len(keys) * i // 5:len(keys) * (i + 1) // 5] for i in range(5)]
    return [100 * sum(value[k] - reference[k] for k in f) / len(f) / largest for f in fifths if f]


def main():
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split()))
    parser.add_argument("reference", help="per-leaf CSV of the reference (leaflux solve --out)")
    parser.add_argument("other", help="per-leaf CSV of the solver compared with it")
    args = parser.parse_args()
    reference, value = load(args.reference), load(args.other)
    for band in sorted({k[1] for k in reference}):
        l2, mean, p95 = errors(reference, value, band)
        print(f"{band}: L2 {l2:.2f} % of max, mean relative {mean:.2f} %, 95th percentile {p95:.2f} %")
        fifths = " ".join(f"{b:+.2f}" for b in bias_by_fifth(reference, value, band))
        print(f"{band}: mean signed error by fifth, darkest to brightest (% of max): {fifths}")


if __name__ == "__main__":
    main()
