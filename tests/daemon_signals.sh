#!/usr/bin/env bash
# leafluxd as a service manager stops it: SIGTERM and SIGINT end it cleanly (exit status 0)
# whether it waits in its poll or not, and --log-file keeps every request with its timing.
# Usage: daemon_signals.sh BUILD_DIR
set -euo pipefail
daemon=$1/server/leafluxd
leaflux=$1/server/leaflux
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "$1"; cat "$out"/*.log 2> /dev/null; exit 1; }

for signal in TERM INT; do
    endpoint=tcp://127.0.0.1:$((20000 + RANDOM % 20000))
    log=$out/$signal.log
    "$daemon" --bind "$endpoint" --log-level debug --log-file "$log" 2> /dev/null &
    pid=$!
    served=no
    for _ in $(seq 50); do
        if "$leaflux" client --endpoint "$endpoint" --timeout 1 status > /dev/null 2>&1; then
            served=yes
            break
        fi
        sleep 0.1
    done
    test $served = yes || fail "leafluxd did not answer on $endpoint"
    kill -s "$signal" $pid
    status=0
    wait $pid || status=$?
    test $status -eq 0 || fail "leafluxd exited with status $status on SIG$signal"
    grep -q "leafluxd stopped" "$log" || fail "no clean stop in the log after SIG$signal"
    grep -Eq "request [0-9]+: status: done in [0-9.]+ ms" "$log" ||
        fail "the status request is not in the log with its timing"
done
echo "leafluxd stops cleanly on SIGTERM and SIGINT"
