#!/usr/bin/env bash
# Installs what leaflux needs, builds it (release preset, 2 jobs) and runs the test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release -G Ninja > /dev/null
cmake --build --preset release
# The tests' files in a folder of this run's own, removed after it: a test that reads a file
# it did not write fails here, instead of passing where an earlier run left one behind.
scratch=$(mktemp -d "${TMPDIR:-/tmp}/leaflux-tests.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
TEST_TMPDIR="$scratch" TMPDIR="$scratch" ctest --preset release -j2 "$@"
