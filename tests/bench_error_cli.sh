#!/usr/bin/env bash
# `leaflux bench error` as users run it: a small canopy, the reference solved once and
# then read from the cache, a damaged cache file solved again, the CSV and plot written,
# a missing scene refused with its name, an --out or --cache that cannot be written refused
# before the reference is solved, a reference on a sample of plants.
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
# Output paths are checked before the reference is solved, and named.
touch "$out/a_file"
status=0
"$leaflux" bench error --scene "$out/canopy.scene.txtpb" --out "$out/a_file/error" \
    --cache "$out/cache" > "$out/unwritable.log" 2>&1 || status=$?
test $status -ne 0 || fail "an --out below a file was accepted"
grep -q -- "--out $out/a_file/error/canopy.csv: cannot be written" "$out/unwritable.log" ||
    fail "an unwritable --out is not named: $(cat "$out/unwritable.log")"
grep -q "leaves;" "$out/unwritable.log" && fail "the scene was solved before --out was checked"
status=0
"$leaflux" bench error --scene "$out/canopy.scene.txtpb" --out "$out/error" \
    --cache "$out/a_file" > "$out/unwritable.log" 2>&1 || status=$?
test $status -ne 0 || fail "a --cache below a file was accepted"
grep -q -- "--cache $out/a_file/reference-.*: cannot be written" "$out/unwritable.log" ||
    fail "an unwritable --cache is not named: $(cat "$out/unwritable.log")"
grep -q "solving the reference" "$out/unwritable.log" &&
    fail "the reference was solved before --cache was checked"
# A sample of a plantation's plants: the reference and the errors over their leaves only,
# its balance not given (it closes over no part of the scene); more plants than the scene
# has, refused with the option's name.
"$leaflux" generate --leaves 30 --seed 2 --rows 2 --columns 2 --trees 4 --sky-cones turtle46 \
    --out "$out/trees.scene.txtpb" > /dev/null
"$leaflux" bench error --scene "$out/trees.scene.txtpb" --out "$out/error" --cache "$out/cache" \
    --reference-samples 256 --mc-samples 16 --no-hrc --no-direct --sample-plants 2 --no-plot \
    > "$out/sample.log" 2>&1 || fail "a sample of plants failed: $(cat "$out/sample.log")"
grep -q "trees: 60 leaves" "$out/sample.log" || fail "the sample should count 2 plants' 60 leaves"
grep -q "^trees,60,mc,reference samples=256,PAR,.*,nan$" "$out/error/trees.csv" ||
    fail "the sample's reference should give no balance: $(cat "$out/error/trees.csv")"
status=0
"$leaflux" bench error --scene "$out/trees.scene.txtpb" --out "$out/error" --cache "$out/cache" \
    --sample-plants 5 --no-plot > "$out/toomany.log" 2>&1 || status=$?
test $status -ne 0 && grep -q -- "--sample-plants" "$out/toomany.log" ||
    fail "more plants than the scene has should be refused: $(cat "$out/toomany.log")"
# With --instanced-merge, a merged instanced run at each ε.
"$leaflux" bench error --scene "$out/trees.scene.txtpb" --out "$out/error" --cache "$out/cache" \
    --reference-samples 256 --mc-samples 16 --hrc-epsilon 1e-3 --no-direct --no-plot \
    --instanced-epsilon 1e-3,3e-3 --instanced-merge 4096 > "$out/merged.log" 2>&1 ||
    fail "merged instanced runs failed: $(cat "$out/merged.log")"
for epsilon in 0.001 0.003; do
    grep -q "^trees,120,instanced,epsilon=$epsilon merge-triangles=4096,NIR," "$out/error/trees.csv" ||
        fail "no merged run at ε = $epsilon: $(cut -d, -f3-5 "$out/error/trees.csv")"
done
echo "leaflux bench error: reference cached and reused, damaged cache solved again, CSV written," \
     "unwritable --out and --cache refused first, a sample of plants compared on their leaves," \
     "merged instanced runs at every ε"
