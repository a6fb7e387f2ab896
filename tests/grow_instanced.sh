#!/usr/bin/env bash
# Two runs of the wall-hole plant grown with instancing on one phase-function database,
# with leafluxd stopped (SIGTERM) and started again between them: the first computes the
# plant's phase functions, the second computes none and grows the same plant. A stop
# leaves the database's rows in its file (its WAL flushed). Then per-branch light with
# instancing, whose axes are solved whole.
# Usage: grow_instanced.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
out=$(mktemp -d)
endpoint=tcp://127.0.0.1:5578
daemon=
start_daemon() {
    "$build/server/leafluxd" --bind "$endpoint" --phase-db "$out/phase.db" >> "$out/leafluxd.log" 2>&1 &
    daemon=$!
    for _ in $(seq 50); do
        "$build/server/leaflux" client --endpoint "$endpoint" --timeout 1 status > /dev/null 2>&1 && return
        sleep 0.2
    done
    echo "leafluxd did not start"; cat "$out/leafluxd.log"; exit 1
}
trap 'kill $daemon 2> /dev/null || true; rm -rf "$out"' EXIT
grow() {
    "$build/growth_stub/leaflux-grow" --scenario "$source/growth_stub/scenarios/wall-hole.txtpb" \
        --cycles 8 --endpoint "$endpoint" --solver instanced --out "$out/$1" --quiet "${@:2}"
}
# The sum of a cycles.csv column, by name.
column_sum() {
    awk -F, -v name="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == name) c = i; next }
                          { s += $c } END { print s + 0 }' "$1"
}
start_daemon
grow first
kill -TERM $daemon
wait $daemon
if [ -s "$out/phase.db-wal" ]; then echo "the WAL was not flushed into the database on SIGTERM"; exit 1; fi
start_daemon
grow second
computed=$(column_sum "$out/first/cycles.csv" phase_computed)
again=$(column_sum "$out/second/cycles.csv" phase_computed)
reused=$(column_sum "$out/second/cycles.csv" phase_reused)
test "$computed" -gt 0 || { echo "the first run computed no phase function"; exit 1; }
test "$again" -eq 0 || { echo "the restarted daemon computed $again phase functions again"; exit 1; }
# The same plant: the same light every cycle, from the same functions.
cut -d, -f1-5 "$out/first/cycles.csv" > "$out/a.csv"
cut -d, -f1-5 "$out/second/cycles.csv" > "$out/b.csv"
diff "$out/a.csv" "$out/b.csv" || { echo "the second run grew another plant"; exit 1; }
# Per-branch light: every leaf gets its axis's light, axes solved whole.
"$build/growth_stub/leaflux-grow" --scenario "$source/growth_stub/scenarios/wall-hole.txtpb" \
    --cycles 8 --endpoint "$endpoint" --solver instanced --branch-light --out "$out/branch" --quiet
awk -F, 'NR > 1 && !($5 > 0) { print "cycle " $1 ": no PAR absorbed with branch light"; exit 1 }' \
    "$out/branch/cycles.csv"
"$build/server/leaflux" client --endpoint "$endpoint" shutdown > /dev/null
wait $daemon
echo "instanced growth: $computed phase functions computed in the first run, 0 of $reused in the second; branch light"
