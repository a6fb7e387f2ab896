#!/usr/bin/env bash
# leaflux render as a user meets it: a picture solved now and one drawn from the CSV that
# solve wrote are the same PNG; the camera, the size and the output path are checked before
# the solve, the errors naming the field; values beyond --range are reported.
# Usage: render_cli.sh BUILD_DIR
set -euo pipefail
leaflux=$1/server/leaflux
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $1"; tail -20 "$out/last.log" 2> /dev/null; exit 1; }
refused() {
    if "$@" > "$out/last.log" 2>&1; then fail "accepted: $*"; fi
}

"$leaflux" generate --leaves 200 --out "$out/tree.scene.txtpb" > /dev/null
camera="eye=6,-6,4 look=0,0,2.5"
"$leaflux" render --scene "$out/tree.scene.txtpb" --camera "$camera" --size 320x240 \
    --out "$out/pictures/solved.png" --quiet > "$out/last.log" || fail "render"
grep -q "wrote $out/pictures/solved.png: 320 x 288, PAR irradiance" "$out/last.log" || fail "render's summary"
head -c 8 "$out/pictures/solved.png" | od -An -tx1 | grep -q "89 50 4e 47 0d 0a 1a 0a" || fail "not a PNG"

"$leaflux" solve --scene "$out/tree.scene.txtpb" --out "$out/leaves.csv" --quiet > /dev/null
"$leaflux" render --scene "$out/tree.scene.txtpb" --from "$out/leaves.csv" --camera "$camera" \
    --size 320x240 --out "$out/from_csv.png" > "$out/last.log" || fail "render --from"
cmp -s "$out/pictures/solved.png" "$out/from_csv.png" || fail "render --from draws another picture"

# Checked before any solve: the log has no solve line.
refused "$leaflux" render --scene "$out/tree.scene.txtpb" --camera "eye=1,1,1 look=1,1,1" --out "$out/x.png"
grep -q "camera.look" "$out/last.log" || fail "eye = look: no camera.look in the error"
grep -q "receivers" "$out/last.log" && fail "eye = look: refused only after loading the scene"
refused "$leaflux" render --scene "$out/tree.scene.txtpb" --camera "$camera fov=0" --out "$out/x.png"
grep -q "camera.fov" "$out/last.log" || fail "fov=0: no camera.fov in the error"
refused "$leaflux" render --scene "$out/tree.scene.txtpb" --camera "eye=nan,0,1 look=0,0,0" --out "$out/x.png"
grep -q "camera.eye" "$out/last.log" || fail "NaN eye: no camera.eye in the error"
refused "$leaflux" render --scene "$out/tree.scene.txtpb" --camera "$camera" --size 320 --out "$out/x.png"
grep -q -- "--size" "$out/last.log" || fail "--size 320: no --size in the error"
refused "$leaflux" render --scene "$out/tree.scene.txtpb" --camera "$camera" --out "$out/leaves.csv/x.png"
grep -q -- "--out" "$out/last.log" || fail "unwritable --out: no --out in the error"
refused "$leaflux" render --scene "$out/tree.scene.txtpb" --camera "$camera" --band UV --out "$out/x.png"
grep -q -- "--band" "$out/last.log" || fail "--band UV: no --band in the error"
grep -q "receivers" "$out/last.log" && fail "--band UV: refused only after the solve"

"$leaflux" render --scene "$out/tree.scene.txtpb" --from "$out/leaves.csv" --camera "$camera" \
    --size 160x120 --range 0,50 --out "$out/range.png" > "$out/last.log" || fail "render --range"
grep -q "beyond the scale (hatched)" "$out/last.log" || fail "--range 0,50: nothing reported beyond it"
echo "render_cli passed"
