#!/usr/bin/env bash
# Benchmarks (not tests): ray engine rays/s, Monte Carlo cost and daemon latency, tables
# printed and CSV written to out/bench/. Takes a few minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release -G Ninja > /dev/null
cmake --build --preset release
mkdir -p out/bench
build/release/tests/leaflux_bench_raytrace --benchmark_out=out/bench/raytrace.csv --benchmark_out_format=csv
build/release/tests/leaflux_bench_reference out/bench/reference.csv
build/release/tests/leaflux_bench_daemon out/bench/daemon.csv
