#!/usr/bin/env bash
# Builds the Java client of leafluxd with protoc, javac and jar alone (no Maven, no network):
# generates the protobuf classes from proto/leaflux.proto, compiles them and java/src
# against Debian's protobuf.jar and jeromq.jar, and writes OUT_DIR/leaflux-client.jar.
# `java -jar OUT_DIR/leaflux-client.jar --help` runs the example growth loop.
# Usage: java/build.sh OUT_DIR        (LEAFLUX_JAVA_JARS: where the two jars are, default
#                                      /usr/share/java)
set -euo pipefail
if [ $# -ne 1 ]; then
    echo "usage: java/build.sh OUT_DIR" >&2
    exit 2
fi
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source=$(dirname "$here")
mkdir -p "$1"
out=$(cd "$1" && pwd)
jars=${LEAFLUX_JAVA_JARS:-/usr/share/java}
for tool in protoc javac jar; do
    command -v "$tool" > /dev/null || { echo "java/build.sh: $tool not found" >&2; exit 1; }
done
for j in protobuf.jar jeromq.jar; do
    test -f "$jars/$j" || { echo "java/build.sh: $jars/$j not found (Debian: libprotobuf-java, libjeromq-java)" >&2; exit 1; }
done
classpath=$jars/protobuf.jar:$jars/jeromq.jar

work=$out/java-build
rm -rf "$work"
mkdir -p "$work/proto" "$work/generated" "$work/classes"
# The schema with Java options added, in a copy: proto/leaflux.proto, and what C++ and
# Python make of it, stay as they are. The wire format does not depend on these options.
sed '/^package leaflux\.v1;$/a\
option java_package = "org.leaflux.v1";\
option java_multiple_files = true;\
option java_outer_classname = "LeafluxProto";' "$source/proto/leaflux.proto" > "$work/proto/leaflux.proto"
grep -q '^option java_package' "$work/proto/leaflux.proto" ||
    { echo "java/build.sh: no 'package leaflux.v1;' line in proto/leaflux.proto" >&2; exit 1; }
protoc --proto_path="$work/proto" --java_out="$work/generated" "$work/proto/leaflux.proto"

# Generated code first (its warnings are protoc's), then ours with every warning an error.
find "$work/generated" -name '*.java' > "$work/generated.txt"
javac --release 17 -nowarn -encoding UTF-8 -cp "$classpath" -d "$work/classes" @"$work/generated.txt"
find "$here/src" -name '*.java' > "$work/sources.txt"
javac --release 17 -Xlint:all -Werror -encoding UTF-8 -cp "$classpath:$work/classes" \
    -d "$work/classes" @"$work/sources.txt"

# The manifest names the two jars, so that `java -jar` finds them.
printf 'Class-Path: %s %s\n' "file:$jars/protobuf.jar" "file:$jars/jeromq.jar" > "$work/manifest.txt"
jar --create --file "$out/leaflux-client.jar" --manifest "$work/manifest.txt" \
    --main-class org.leaflux.example.GrowthLoop -C "$work/classes" .
echo "wrote $out/leaflux-client.jar"
