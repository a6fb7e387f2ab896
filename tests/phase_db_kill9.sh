#!/usr/bin/env bash
# A process writing the phase database killed with SIGKILL at random moments, 30 times
# (the first kills fall during the file's creation): afterwards PRAGMA integrity_check and
# every row's checksum are clean, and every row reported committed before a kill is there.
# Usage: phase_db_kill9.sh BUILD_DIR [KILLS]
set -euo pipefail
build=$1 kills=${2:-30}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
db=$out/phase.db
writer=$build/tests/leaflux_phase_db_writer
leaflux=$build/server/leaflux
RANDOM=2026  # the same moments each run

for run in $(seq "$kills"); do
    : > "$out/committed.$run"  # a writer killed before its exec opens nothing
    "$writer" "$db" "$run" > "$out/committed.$run" 2>> "$out/writer.err" &
    pid=$!
    # 0 to 0.4 s; the first runs die sooner, while the file is made
    if [ "$run" -le 3 ]; then delay=$((RANDOM % 20)); else delay=$((RANDOM % 400)); fi
    sleep "$(printf '0.%03d' "$delay")"
    kill -9 "$pid" 2> /dev/null || true
    wait "$pid" 2> /dev/null || true
done

if [ -s "$out/writer.err" ]; then
    echo "FAIL: the writer reported errors:"; cat "$out/writer.err"; exit 1
fi
if ! "$leaflux" phase-db verify --db "$db" > "$out/verify.txt"; then
    echo "FAIL: the database is damaged:"; cat "$out/verify.txt"; exit 1
fi
"$leaflux" phase-db list --keys --db "$db" | sort -u > "$out/present"
# Only whole lines: a line cut by the kill was not reported committed.
for run in $(seq "$kills"); do
    while IFS= read -r key; do echo "$key"; done < "$out/committed.$run"
done | sort -u > "$out/committed"
missing=$(comm -23 "$out/committed" "$out/present" | wc -l)
committed=$(wc -l < "$out/committed")
present=$(wc -l < "$out/present")
# Rows in the file but never reported: kills that fell between a commit and its report.
echo "$kills kills: $committed rows reported committed, $present rows in the file" \
    "($((present - committed)) committed but not yet reported), $missing missing"
tail -1 "$out/verify.txt"
if [ "$committed" -eq 0 ]; then echo "FAIL: no row was ever committed"; exit 1; fi
if [ "$missing" -ne 0 ]; then
    echo "FAIL: committed rows lost:"; comm -23 "$out/committed" "$out/present" | head; exit 1
fi
echo "PASS"
