#!/usr/bin/env bash
# The main job: starts leafluxd, grows the `wall-hole` plant (a plant in a room lit only
# through a hole in a wall) for 25 cycles with leaflux-grow, writes its CSVs, the PLY and
# pictures of cycles 2, 9, 13, 17 and 25 and a growth plot, grows it again with direct
# light only, with instancing (the instanced solver and its default policy, which leaves
# structures of 10 leaves or fewer to the structure holding them; its phase functions kept
# in the daemon's database, by default under ~/.local/share/leaflux) and with instancing of
# every structure, compares each with the first plant organ by organ (paper Fig. 19 and
# 15), then stops the daemon cleanly; all in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release -G Ninja > /dev/null
# Only what the demo and the Python examples run (scripts/test.sh builds everything, tests
# and benchmarks too).
cmake --build --preset release --target leafluxd leaflux leaflux-grow \
    leaflux_proto_python leaflux_grow_python
out=out/demo
rm -rf "$out" && mkdir -p "$out"
B=build/release
endpoint=${LEAFLUX_ENDPOINT:-tcp://127.0.0.1:5575}

# Each run gets a daemon of its own, so that its peak memory is its own.
start_daemon() {
    "$B/server/leafluxd" --bind "$endpoint" >> "$out/leafluxd.log" 2>&1 &
    daemon=$!
    trap 'kill $daemon 2> /dev/null || true' EXIT
    for _ in $(seq 50); do  # until it answers
        "$B/server/leaflux" client --endpoint "$endpoint" --timeout 1 status > /dev/null 2>&1 && break
        sleep 0.2
    done
}
stop_daemon() {
    "$B/server/leaflux" client --endpoint "$endpoint" shutdown > /dev/null
    wait $daemon
    trap - EXIT
}

start_daemon
"$B/growth_stub/leaflux-grow" --scenario growth_stub/scenarios/wall-hole.txtpb --cycles 25 \
    --endpoint "$endpoint" --out "$out" --ply-cycles 2,9,13,17,25 --png-cycles 2,9,13,17,25 \
    | tee "$out/grow.txt"
stop_daemon
start_daemon
"$B/growth_stub/leaflux-grow" --scenario growth_stub/scenarios/wall-hole.txtpb --cycles 25 \
    --endpoint "$endpoint" --out "$out/direct_only" --direct-only --quiet | tee -a "$out/grow.txt"
stop_daemon
start_daemon
"$B/growth_stub/leaflux-grow" --scenario growth_stub/scenarios/wall-hole.txtpb --cycles 25 \
    --endpoint "$endpoint" --out "$out/instanced" --solver instanced --quiet | tee -a "$out/grow.txt"
stop_daemon
start_daemon
"$B/growth_stub/leaflux-grow" --scenario growth_stub/scenarios/wall-hole.txtpb --cycles 25 \
    --endpoint "$endpoint" --out "$out/instanced_every" --solver instanced \
    --policy proto/policies/every_structure.txtpb --quiet | tee -a "$out/grow.txt"
stop_daemon

/usr/bin/python3 examples/plot_growth.py "$out" "full light" "$out/direct_only" "direct light only"
/usr/bin/python3 examples/compare_growth.py "$out" full "$out/direct_only" direct_only \
    "$out/growth_comparison"
/usr/bin/python3 examples/compare_growth.py "$out" hrc "$out/instanced" instanced \
    "$out/instancing_comparison"
/usr/bin/python3 examples/compare_growth.py "$out" hrc "$out/instanced_every" \
    instanced_every_structure "$out/instancing_every_comparison"
echo "results in $out/: cycles.csv plants.csv phytomers.csv cycle{2,9,13,17,25}.{ply,scene.txtpb,csv,png}" \
     "growth.png growth_comparison.{csv,png} instancing_comparison.{csv,png}" \
     "instancing_every_comparison.{csv,png} grow.txt direct_only/ instanced/" \
     "instanced_every/ leafluxd.log"
