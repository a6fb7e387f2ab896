#!/usr/bin/env bash
# The Java client (java/) as GroIMP users would couple it: builds leaflux-client.jar into
# the build tree with java/build.sh, starts leafluxd on a free loopback port, and checks
#  - the example growth loop: exit code 0, every cycle's absorbed PAR finite and positive,
#    the leaf count growing each cycle, a plausible leaf area (under 50 dm²);
#  - typed errors: a cycle of an unknown session is ERROR_CODE_UNKNOWN_SESSION (field
#    "session"), a cycle sent twice ERROR_CODE_INVALID_ARGUMENT (field "number"); a cycle
#    given a resync source after its session was closed is resynced and lit;
#  - the loop through a kill -9 of leafluxd and a restart: resynced, the same 8 cycles;
#  - a reply of another request's id, and a frame that is no Reply, dropped;
#  - a timeout against no daemon, within its time and naming the endpoint.
# Exits 77 (ctest SKIP_RETURN_CODE) when javac, jar, protoc or Debian's protobuf.jar and
# jeromq.jar (libprotobuf-java, libjeromq-java) are missing.
# Usage: java_client_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
jars=${LEAFLUX_JAVA_JARS:-/usr/share/java}
for tool in java javac jar protoc; do
    command -v "$tool" > /dev/null || { echo "SKIP: $tool not found (Debian: default-jdk-headless, protobuf-compiler)"; exit 77; }
done
for j in protobuf.jar jeromq.jar; do
    test -f "$jars/$j" || { echo "SKIP: $jars/$j not found (Debian: libprotobuf-java, libjeromq-java)"; exit 77; }
done

out=$(mktemp -d)
daemon= grower=
cleanup() {
    for p in $daemon $grower; do
        kill "$p" 2> /dev/null || true
        wait "$p" 2> /dev/null || true
    done
    rm -rf "$out"
}
trap cleanup EXIT
fail() { echo "FAIL: $1"; for f in "$out"/*.out "$out"/*.err "$out"/*.log; do echo "== $f"; tail -20 "$f"; done 2> /dev/null; exit 1; }

"$source/java/build.sh" "$build/java" > "$out/build.out" 2> "$out/build.err" || fail "java/build.sh failed"
jar=$build/java/leaflux-client.jar
classpath=$jar:$jars/protobuf.jar:$jars/jeromq.jar

# Starts leafluxd on `bind` (one thread a solve: the light is the same bit for bit in
# every run) and sets `endpoint` from its log's first line.
start_daemon() {  # bind, log
    "$build/server/leafluxd" --bind "$1" --solver-threads 1 --log-file "$2" 2> /dev/null &
    daemon=$!
    endpoint=
    for _ in $(seq 250); do
        endpoint=$(grep -o "serving tcp://[^ ]*" "$2" 2> /dev/null | cut -d' ' -f2) || true
        [ -n "$endpoint" ] && return 0
        sleep 0.02
    done
    fail "leafluxd did not start on $1"
}
start_daemon "tcp://127.0.0.1:*" "$out/daemon.log"

# The growth loop, 5 cycles.
java -jar "$jar" --endpoint "$endpoint" --cycles 5 > "$out/growth.out" 2> "$out/growth.err" ||
    fail "the growth loop exited $?"
cat "$out/growth.out"
awk '
    $1 ~ /^[0-9]+$/ {
        rows++
        if ($1 != rows) { print "cycle " $1 " in row " rows; bad = 1 }
        if (!($4 + 0 > 0) || tolower($4) ~ /nan|inf/) { print "cycle " $1 ": absorbed PAR " $4 " is not finite and positive"; bad = 1 }
        if (rows > 1 && $2 + 0 <= leaves) { print "cycle " $1 ": " $2 " leaves after " leaves; bad = 1 }
        if (!($3 + 0 > 0 && $3 + 0 < 50)) { print "cycle " $1 ": leaf area " $3 " dm2 is not plausible"; bad = 1 }
        leaves = $2 + 0
    }
    END {
        if (rows != 5) { print rows " cycles printed, not 5"; bad = 1 }
        exit bad
    }' "$out/growth.out" > "$out/growth.check" || fail "the growth loop's output: $(cat "$out/growth.check")"
grep -q "^closed session after 5 cycles" "$out/growth.out" || fail "the growth loop did not close its session"

# Killed mid-growth (SIGKILL) and started again on the same port: the loop's cycle times
# out, or finds its session unknown; the client reconnects, resyncs and sends it again,
# and the loop ends as an uninterrupted run does.
java -jar "$jar" --endpoint "$endpoint" --cycles 8 > "$out/reference.out" 2> "$out/reference.err" ||
    fail "the uninterrupted 8-cycle growth loop exited $?"
java -jar "$jar" --endpoint "$endpoint" --cycles 8 --cycle-timeout-ms 3000 > "$out/faulted.out" \
    2> "$out/faulted.err" &
grower=$!
for _ in $(seq 3000); do
    grep -q "^ *3 " "$out/faulted.out" 2> /dev/null && break
    sleep 0.02
done
grep -q "^ *3 " "$out/faulted.out" || fail "the faulted growth loop did not reach cycle 3"
kill -9 "$daemon"
wait "$daemon" 2> /dev/null || true
start_daemon "$endpoint" "$out/restarted.log"
wait "$grower" || fail "the growth loop did not finish after the restart"
grower=
grep -q "resyncing" "$out/faulted.err" || fail "the growth loop did not resync: the kill missed"
grep -m1 "resyncing" "$out/faulted.err"
cmp -s "$out/reference.out" "$out/faulted.out" ||
    { diff "$out/reference.out" "$out/faulted.out"; fail "the growth differs after the restart"; }
echo "killed and restarted leafluxd mid-growth: the loop resynced, its 8 cycles as without"

# Typed errors from the daemon.
java -cp "$classpath" "$source/tests/JavaClientChecks.java" errors "$endpoint" > "$out/errors.out" \
    2> "$out/errors.err" || fail "typed errors"
cat "$out/errors.out"

# Stale replies (another request's id, a frame that is no Reply) dropped, with a stand-in
# daemon.
java -cp "$classpath" "$source/tests/JavaClientChecks.java" stale > "$out/stale.out" \
    2> "$out/stale.err" || fail "stale replies"
cat "$out/stale.out"

# A timeout with no daemon: the running one stopped, its port now free.
kill "$daemon"
wait "$daemon" 2> /dev/null || true
daemon=
java -cp "$classpath" "$source/tests/JavaClientChecks.java" timeout "$endpoint" 1500 \
    > "$out/timeout.out" 2> "$out/timeout.err" || fail "the timeout"
cat "$out/timeout.out"
echo "the Java client grew a plant over 5 cycles and through a restart, got typed errors, resynced, dropped stale replies and timed out naming $endpoint"
