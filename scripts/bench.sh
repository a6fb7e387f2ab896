#!/usr/bin/env bash
# Benchmarks (not tests): ray engine rays/s and Monte Carlo cost, tables printed and CSV
# written to out/bench/. Takes about a minute on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release -G Ninja > /dev/null
cmake --build --preset release
mkdir -p out/bench
build/release/tests/leaflux_bench_raytrace --benchmark_out=out/bench/raytrace.csv --benchmark_out_format=csv
build/release/tests/leaflux_bench_reference out/bench/reference.csv
