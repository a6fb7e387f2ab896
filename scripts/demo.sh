#!/usr/bin/env bash
# The main job: starts leafluxd, grows the `wall-hole` plant (a plant in a room lit only
# through a hole in a wall) for 25 cycles with leaflux-grow, writes its CSVs, the PLY and
# pictures of cycles 2, 9, 13, 17 and 25 and a growth plot, grows it again with direct
# light only for comparison, then stops the daemon cleanly; all in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release -G Ninja > /dev/null
cmake --build --preset release
out=out/demo
rm -rf "$out" && mkdir -p "$out"
B=build/release
endpoint=${LEAFLUX_ENDPOINT:-tcp://127.0.0.1:5575}

"$B/server/leafluxd" --bind "$endpoint" > "$out/leafluxd.log" 2>&1 &
daemon=$!
trap 'kill $daemon 2> /dev/null || true' EXIT
for _ in $(seq 50); do  # until it answers
    "$B/server/leaflux" client --endpoint "$endpoint" --timeout 1 status > /dev/null 2>&1 && break
    sleep 0.2
done

"$B/growth_stub/leaflux-grow" --scenario growth_stub/scenarios/wall-hole.txtpb --cycles 25 \
    --endpoint "$endpoint" --out "$out" --ply-cycles 2,9,13,17,25 | tee "$out/grow.txt"
"$B/growth_stub/leaflux-grow" --scenario growth_stub/scenarios/wall-hole.txtpb --cycles 25 \
    --endpoint "$endpoint" --out "$out/direct_only" --direct-only --quiet | tee -a "$out/grow.txt"
"$B/server/leaflux" client --endpoint "$endpoint" shutdown > /dev/null
wait $daemon
trap - EXIT

for c in 2 9 13 17 25; do
    /usr/bin/python3 examples/render_ply.py "$out/cycle$c.ply" "$out/cycle$c.png" "wall-hole, cycle $c"
done
/usr/bin/python3 examples/plot_growth.py "$out" "full light" "$out/direct_only" "direct light only"
echo "results in $out/: cycles.csv plants.csv cycle{2,9,13,17,25}.{ply,png} growth.png grow.txt" \
     "direct_only/ leafluxd.log"
