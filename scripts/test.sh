#!/usr/bin/env bash
# Installs what leaflux needs, builds it (release preset, 2 jobs) and runs the test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release -G Ninja > /dev/null
cmake --build --preset release
ctest --preset release -j2 "$@"
