#!/usr/bin/env bash
# leafluxd and leaflux-grow as users run them: the daemon on a loopback port, three cycles
# of the wall-hole plant, a row per cycle and the daemon's picture of the last, 14 more under direct light only in a session of
# their own, then a clean shutdown through the protocol.
# Usage: grow_end_to_end.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
out=$(mktemp -d)
endpoint=tcp://127.0.0.1:5577
"$build/server/leafluxd" --bind "$endpoint" > "$out/leafluxd.log" 2>&1 &
daemon=$!
trap 'kill $daemon 2> /dev/null || true; rm -rf "$out"' EXIT
for _ in $(seq 50); do
    "$build/server/leaflux" client --endpoint "$endpoint" --timeout 1 status > /dev/null 2>&1 && break
    sleep 0.2
done
"$build/growth_stub/leaflux-grow" --scenario "$source/growth_stub/scenarios/wall-hole.txtpb" \
    --cycles 3 --endpoint "$endpoint" --out "$out" --ply-cycles 3 --png-cycles 3 --quiet
test "$(wc -l < "$out/cycles.csv")" -eq 4 || { echo "cycles.csv should have 3 rows"; exit 1; }
test -s "$out/cycle3.ply" || { echo "no PLY for cycle 3"; exit 1; }
# The daemon's picture of cycle 3 (the scenario's picture block) is the one leaflux render
# draws from the cycle's scene and light with the same settings; the CSV's nine digits may
# move a pixel by one level.
"$build/server/leaflux" render --scene "$out/cycle3.scene.txtpb" --from "$out/cycle3.csv" \
    --camera "eye=-0.85,-0.9,0.75 look=0.6,0.05,0.5 fov=60" --side both --size 640x480 \
    --range 0,550 --out "$out/rendered3.png" > /dev/null
/usr/bin/python3 - "$out/cycle3.png" "$out/rendered3.png" <<'PY'
import sys
import matplotlib.image
a, b = (matplotlib.image.imread(p) for p in sys.argv[1:])
assert a.shape == b.shape, (a.shape, b.shape)
delta = abs(a - b)
assert delta.max() <= 1.5 / 255 and (delta > 0).mean() < 1e-3, (delta.max(), (delta > 0).mean())
PY
# Under direct light only the plant sheds organs: from cycle 11 on, deltas remove nodes and
# update others in one change.
"$build/growth_stub/leaflux-grow" --scenario "$source/growth_stub/scenarios/wall-hole.txtpb" \
    --cycles 14 --endpoint "$endpoint" --out "$out/direct_only" --direct-only --quiet
test "$(wc -l < "$out/direct_only/cycles.csv")" -eq 15 || { echo "direct_only/cycles.csv should have 14 rows"; exit 1; }
"$build/server/leaflux" client --endpoint "$endpoint" shutdown > /dev/null
wait $daemon  # exits 0 after a clean shutdown
trap 'rm -rf "$out"' EXIT
echo "leafluxd + leaflux-grow: 3 cycles, 14 under direct light, clean shutdown"
