#!/usr/bin/env bash
# leafluxd killed with SIGKILL in the middle of a growth, and started again on the same
# endpoint: leaflux-grow and the Python client each time out on the cycle in flight,
# reconnect, resync their session and send the cycle again, and finish the growth with
# results identical to those of an uninterrupted run.
# Usage: daemon_kill9.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
out=$(mktemp -d)
pids=()
cleanup() {
    for p in "${pids[@]}"; do
        kill -9 "$p" 2> /dev/null || true
        wait "$p" 2> /dev/null || true
    done
    rm -rf "$out"
}
trap cleanup EXIT
fail() { echo "FAIL: $1"; for f in "$out"/*.log "$out"/*.err; do echo "== $f"; tail -20 "$f"; done 2> /dev/null; exit 1; }

# One thread a solve: the light is then the same bit for bit in every run.
start_daemon() {  # port, log
    "$build/server/leafluxd" --bind "tcp://127.0.0.1:$1" --solver-threads 1 --workers 2 \
        --log-file "$2" 2> /dev/null &
    daemon=$!
    pids+=("$daemon")
    for _ in $(seq 100); do
        "$build/server/leaflux" client --endpoint "tcp://127.0.0.1:$1" --timeout 1 status \
            > /dev/null 2>&1 && return 0
        sleep 0.1
    done
    fail "leafluxd did not answer on port $1"
}
wait_for_line() {  # file, pattern, seconds
    for _ in $(seq $((50 * $3))); do
        grep -q "$2" "$1" 2> /dev/null && return 0
        sleep 0.02
    done
    fail "no '$2' in $1 within $3 s"
}
# Kills the daemon once `file` shows `pattern`, and starts another on the same port.
kill_and_restart() {  # file, pattern, port, log
    wait_for_line "$1" "$2" 60
    kill -9 "$daemon"
    wait "$daemon" 2> /dev/null || true
    start_daemon "$3" "$4"
}

port=$((20000 + RANDOM % 20000))
scenario=$source/growth_stub/scenarios/wall-hole.txtpb
cycles=10
# Monte Carlo with enough paths that a cycle takes a while (cycles 5 to 10 together about
# a second): the kill lands in a solve.
grow=("$build/growth_stub/leaflux-grow" --scenario "$scenario" --cycles "$cycles" --solver mc
      --samples 2048 --cycle-timeout 4)

# leaflux-grow: uninterrupted, then killed after cycle 4.
start_daemon "$port" "$out/reference.log"
"${grow[@]}" --endpoint "tcp://127.0.0.1:$port" --out "$out/reference" > "$out/reference.out" \
    2> "$out/reference.err" || fail "the uninterrupted growth failed"
"${grow[@]}" --endpoint "tcp://127.0.0.1:$port" --out "$out/faulted" > "$out/faulted.out" \
    2> "$out/faulted.err" &
grower=$!
pids+=("$grower")
kill_and_restart "$out/faulted.out" "^cycle   4:" "$port" "$out/restarted.log"
wait "$grower" || fail "leaflux-grow did not finish after the restart"
grep -q "resync" "$out/faulted.err" || fail "leaflux-grow did not resync: the kill missed"
grep -m1 "resync" "$out/faulted.err"
# Every column but the timings (solve, round trip, daemon memory) must be identical.
for file in cycles.csv plants.csv phytomers.csv; do
    cut -d, -f1-8 "$out/reference/$file" > "$out/a"
    cut -d, -f1-8 "$out/faulted/$file" > "$out/b"
    test "$(wc -l < "$out/a")" -gt "$cycles" || fail "$file has too few rows"
    cmp -s "$out/a" "$out/b" || { diff "$out/a" "$out/b" | head; fail "$file differs after the restart"; }
done

# The Python client: the same, with a rosette.
export LEAFLUX_BUILD=$build
python=(/usr/bin/python3 "$source/examples/foreign_growth.py" --endpoint "tcp://127.0.0.1:$port"
        --cycles 12 --samples 20000 --cycle-timeout 4)
"${python[@]}" --csv "$out/rosette_reference.csv" > "$out/rosette_reference.out" \
    2> "$out/rosette_reference.err" || fail "the uninterrupted rosette failed"
"${python[@]}" --csv "$out/rosette_faulted.csv" > "$out/rosette_faulted.out" \
    2> "$out/rosette_faulted.err" &
grower=$!
pids+=("$grower")
kill_and_restart "$out/rosette_faulted.out" "^ *5 " "$port" "$out/rosette_restarted.log"
wait "$grower" || fail "the Python rosette did not finish after the restart"
grep -q "resync" "$out/rosette_faulted.err" || fail "the Python client did not resync: the kill missed"
grep -m1 "resync" "$out/rosette_faulted.err"
cmp -s "$out/rosette_reference.csv" "$out/rosette_faulted.csv" ||
    { diff "$out/rosette_reference.csv" "$out/rosette_faulted.csv" | head; fail "the rosette differs after the restart"; }
echo "killed and restarted leafluxd mid-growth: leaflux-grow and the Python client resynced, results identical"
