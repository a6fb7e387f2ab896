#!/usr/bin/env bash
# `leaflux bench error` as users run it: a small canopy, the reference solved once and
# then read from the cache, a damaged cache file solved again, the CSV and plot written,
# a missing scene refused with its name.
# Usage: bench_error_cli.sh BUILD_DIR
set -euo pipefail
leaflux=$1/server/leaflux
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$leaflux" generate --random-canopy --canopy-leaves 60 --sky-cones turtle46 \
    --out "$out/canopy.scene.txtpb" > /dev/null
bench() {
    "$leaflux" bench error --scene "$out/canopy.scene.txtpb" --out "$out/error" \
        --cache "$out/cache" --reference-samples 256 --mc-samples 16,64 --hrc-epsilon 1e-3 "$@" 2>&1
}
fail() { echo "$1"; exit 1; }

bench > "$out/first.log"
grep -q "solving the reference" "$out/first.log" || fail "the first run should solve the reference"
# header + 2 bands × (reference, mc 16, mc 64, hrc 1e-3, direct)
test "$(wc -l < "$out/error/canopy.csv")" -eq 11 || fail "canopy.csv should have 10 rows"
head -1 "$out/error/canopy.csv" | grep -q "l2_pct_of_max,mean_rel_pct,p95_rel_pct,reference_floor_pct" ||
    fail "canopy.csv lacks the error columns"
if /usr/bin/python3 -c "import matplotlib" 2> /dev/null; then
    test -s "$out/error/canopy.png" || fail "no plot"
fi

bench --no-plot > "$out/second.log"
grep -q "reference from" "$out/second.log" || fail "the second run should read the cached reference"
cmp <(grep "^canopy *mc *reference" "$out/first.log") <(grep "^canopy *mc *reference" "$out/second.log") ||
    fail "the cached reference should give the same row"

truncate -s 100 "$out"/cache/reference-*.bin
bench --no-plot > "$out/third.log"
grep -q "solving the reference" "$out/third.log" || fail "a damaged cache file should be solved again"

status=0
"$leaflux" bench error --scene "$out/missing.txtpb" --out "$out/error" > "$out/missing.log" 2>&1 || status=$?
test $status -ne 0 && grep -q "missing.txtpb" "$out/missing.log" || fail "a missing scene should be named"
echo "leaflux bench error: reference cached and reused, damaged cache solved again, CSV written"
