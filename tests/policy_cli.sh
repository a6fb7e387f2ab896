#!/usr/bin/env bash
# `leaflux policy check` as users run it: the groups of a generated tree under the shipped
# policies, a scene file given with --scene, and a bad policy refused with its location.
# Usage: policy_cli.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
leaflux=$1/server/leaflux
policies=$2/proto/policies
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $1"; cat "$out"/*.txt 2> /dev/null | tail -30; exit 1; }

# A 1000-leaf tree: 1 plant, a trunk, 10 branches of 100 leaves, 100 shoots of 10.
"$leaflux" policy check --policy "$policies/every_structure.txtpb" --leaves 1000 > "$out/every.txt"
grep -q '^112 instantiable structures, 4 groups, 0 in no bin' "$out/every.txt" ||
    fail "every-structure policy: not 112 structures in 4 groups"
grep -A1 -x 'axis|leaves\[8,11)' "$out/every.txt" | grep -q 'members 100, leaves 10 / 10 / 10' ||
    fail "every-structure policy: the 100 shoots are not one group"
grep -A1 -x 'axis|leaves\[91,128)' "$out/every.txt" | grep -q 'members 10,' ||
    fail "every-structure policy: the 10 branches are not one group"
# The default leaves the shoots of 10 leaves to their branches, and bins the inclination:
# the generated tree's branches all lean 30 to 60° from the vertical, its trunk stands.
"$leaflux" policy check --policy "$policies/default.txtpb" --leaves 1000 > "$out/default.txt"
grep -q '^112 instantiable structures, 3 groups, 100 in no bin' "$out/default.txt" ||
    fail "default policy: not 3 groups with the 100 shoots in no bin"
grep -A1 -x 'axis|leaves\[91,128)|incl\[30,60)' "$out/default.txt" | grep -q 'members 10,' ||
    fail "default policy: the 10 branches are not one group"
grep -qx 'axis|leaves\[1000,10000\]|incl\[0,30)' "$out/default.txt" ||
    fail "default policy: the trunk is not upright"

# Beyond the cap of 10^4 leaves, one fixed original per type.
"$leaflux" policy check --policy "$policies/default.txtpb" --leaves 20000 > "$out/large.txt"
grep -qx 'plant|large' "$out/large.txt" || fail "a 20000-leaf plant is not plant|large"
grep -qx 'axis|large' "$out/large.txt" || fail "a 20000-leaf trunk is not axis|large"

# The same tree from a scene file gives the same groups.
"$leaflux" generate --leaves 1000 --no-ground --out "$out/tree.scene.txtpb" > /dev/null 2>&1
"$leaflux" policy check --policy "$policies/generated_tree.txtpb" --scene "$out/tree.scene.txtpb" \
    > "$out/fitted.txt"
grep -q '^112 instantiable structures, 4 groups' "$out/fitted.txt" ||
    fail "fitted policy on a scene file: not 112 structures in 4 groups"
grep -qx 'axis|leaves\[5,11)|age\[2,3)' "$out/fitted.txt" || fail "fitted policy: no shoot group"

# A misspelt field: exit code 2 and the file's line and column.
printf 'species: "x"\ninstance_type: [NODE_TYPE_AXIS]\n' > "$out/bad.txtpb"
status=0
"$leaflux" policy check --policy "$out/bad.txtpb" > "$out/bad.txt" 2>&1 || status=$?
test "$status" = 2 || fail "a bad policy exits with $status, not 2"
grep -q "parse $out/bad.txtpb:2:[0-9]*: .*instance_type" "$out/bad.txt" ||
    fail "the bad policy's error does not name file:line:column"
echo "policy_cli: ok"
