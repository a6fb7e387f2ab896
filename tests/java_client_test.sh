#!/usr/bin/env bash
# The Java client (java/) as GroIMP users would couple it: builds leaflux-client.jar into
# the build tree with java/build.sh, starts leafluxd on a free loopback port, and checks
#  - the example growth loop: exit code 0, every cycle's absorbed PAR finite and positive,
#    the leaf count growing each cycle, a plausible leaf area (under 50 dm²);
#  - typed errors: a cycle of an unknown session is ERROR_CODE_UNKNOWN_SESSION (field
#    "session"), a cycle sent twice ERROR_CODE_INVALID_ARGUMENT (field "number"); a cycle
#    given a resync source after its session was closed is resynced and lit;
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
daemon=
cleanup() {
    if [ -n "$daemon" ]; then
        kill "$daemon" 2> /dev/null || true
        wait "$daemon" 2> /dev/null || true
    fi
    rm -rf "$out"
}
trap cleanup EXIT
fail() { echo "FAIL: $1"; for f in "$out"/*.out "$out"/*.err "$out"/*.log; do echo "== $f"; tail -20 "$f"; done 2> /dev/null; exit 1; }

"$source/java/build.sh" "$build/java" > "$out/build.out" 2> "$out/build.err" || fail "java/build.sh failed"
jar=$build/java/leaflux-client.jar
classpath=$jar:$jars/protobuf.jar:$jars/jeromq.jar

"$build/server/leafluxd" --bind "tcp://127.0.0.1:*" --solver-threads 1 --log-file "$out/daemon.log" \
    2> /dev/null &
daemon=$!
endpoint=
for _ in $(seq 250); do
    endpoint=$(grep -o "serving tcp://[^ ]*" "$out/daemon.log" 2> /dev/null | cut -d' ' -f2) || true
    [ -n "$endpoint" ] && break
    sleep 0.02
done
[ -n "$endpoint" ] || fail "leafluxd did not start"

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
echo "the Java client grew a plant over 5 cycles, got typed errors, resynced, dropped stale replies and timed out naming $endpoint"
