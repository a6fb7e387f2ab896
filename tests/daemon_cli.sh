#!/usr/bin/env bash
# leafluxd's and leaflux's command lines where they meet the system: the secret key is
# written for its owner alone, endpoints are checked for what they lack, IPv6 loopback is
# loopback, a port in use is reported with its endpoint, and clients name the endpoint
# that does not answer.
# Usage: daemon_cli.sh BUILD_DIR
set -euo pipefail
daemon=$1/server/leafluxd
leaflux=$1/server/leaflux
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
fail() { echo "FAIL: $1"; cat "$out"/*.err 2> /dev/null | tail -20; exit 1; }
answers() { "$leaflux" client --endpoint "$1" --timeout 1 status > /dev/null 2>&1; }

# The secret key: 0600, even over a file that was world-readable.
umask 022
touch "$out/server.secret"
chmod 644 "$out/server.secret"
"$leaflux" keygen --out "$out/server" > /dev/null
test "$(stat -c %a "$out/server.secret")" = 600 ||
    fail "server.secret is $(stat -c %a "$out/server.secret"), not 600"
test "$(stat -c %a "$out/server.public")" = 644 || fail "server.public is not 644"
"$leaflux" keygen --out "$out/keys/server" > /dev/null  # as the README has it: out/keys/server
test -s "$out/keys/server.secret" -a -s "$out/keys/server.public" || fail "keygen made no folder"

# An endpoint without its transport is refused for what it lacks.
port=$((20000 + RANDOM % 20000))
status=0
"$daemon" --bind "127.0.0.1:$port" 2> "$out/scheme.err" || status=$?
test $status -ne 0 || fail "--bind without tcp:// was accepted"
grep -q "tcp://127.0.0.1:$port" "$out/scheme.err" || fail "the missing scheme is not named"
grep -qi "curve" "$out/scheme.err" && fail "a missing scheme is reported as a CurveZMQ matter"

# IPv6 loopback is loopback: served without CurveZMQ.
"$daemon" --bind "tcp://[::1]:$port" 2> "$out/ipv6.err" &
pids+=($!)
served=no
for _ in $(seq 50); do
    if answers "tcp://[::1]:$port"; then served=yes; break; fi
    sleep 0.1
done
test $served = yes || fail "leafluxd on tcp://[::1]:$port did not serve"

# The same port again: refused, naming the endpoint.
"$daemon" --bind "tcp://[::1]:$port" 2> "$out/inuse.err" && fail "a port in use was bound twice"
grep -q "tcp://\[::1\]:$port" "$out/inuse.err" || fail "the port in use is not named"

# A client with no daemon behind its endpoint says which, within its timeout.
status=0
"$leaflux" client --endpoint tcp://127.0.0.1:9 --timeout 1 status > "$out/client.err" 2>&1 ||
    status=$?
test $status -ne 0 || fail "a status without a daemon succeeded"
grep -q "tcp://127.0.0.1:9" "$out/client.err" || fail "the client does not name the endpoint"
"$leaflux" client --help | grep -q "30000" || fail "--help does not give the status timeout"
echo "keygen 0600, --bind checks, IPv6 loopback, port in use and client timeouts named"
