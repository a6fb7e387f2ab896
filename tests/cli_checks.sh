#!/usr/bin/env bash
# The command lines' checks before work, as a user meets them: every --help gives its
# defaults and solve and client open default to the same solver; whole numbers written as
# 1e4; output paths checked (and their folders made) before a solve; generate refuses a
# scene that cannot fit in memory at once, with its estimate, and options its kind of scene
# ignores; leaflux-grow's --ply-cycles and stand options; solve's CSV in W and µmol; client
# cycle --out writes the Python package's CSV, in W and µmol (empty for a band without a
# photon unit), and prints a summary; the example scripts run as they are and answer --help;
# solve --ply writes the scene's triangles with every solver; the instanced solver's --out
# written as it goes; solve --warm-start.
# Usage: cli_checks.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
leaflux=$1/server/leaflux
daemon=$1/server/leafluxd
grow=$1/growth_stub/leaflux-grow
source=$2
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
fail() { echo "FAIL: $1"; tail -20 "$out/last.log" 2> /dev/null; exit 1; }
# Runs a command that must fail; its output in $out/last.log.
refused() {
    if "$@" > "$out/last.log" 2>&1; then fail "accepted: $*"; fi
}

# --help: defaults everywhere, and one default solver.
"$leaflux" solve --help > "$out/solve.help"
grep -E -- "--solver .*=hrc" "$out/solve.help" > /dev/null || fail "solve --help: no =hrc default"
grep -E -- "--samples .*=1024" "$out/solve.help" > /dev/null || fail "solve --help: no samples default"
"$leaflux" client open --help | grep -E -- "--solver .*=hrc" > /dev/null ||
    fail "client open --help: no =hrc default"
"$leaflux" generate --help | grep -E -- "--leaves .*=1000" > /dev/null ||
    fail "generate --help: no leaves default"
"$grow" --help | grep -E -- "--cycle-timeout .*=60" > /dev/null || fail "leaflux-grow --help"
"$daemon" --help | grep -E -- "--workers .*=2" > /dev/null || fail "leafluxd --help shows no default"

# The example scripts: runnable as they are (/usr/bin/python3, the execute bit), --help.
for script in "$source"/examples/*.py; do
    grep -q '__main__' "$script" || continue  # a module of the others
    test -x "$script" || fail "$script: no execute bit"
    test "$(head -1 "$script")" = "#!/usr/bin/python3" || fail "$script: not #!/usr/bin/python3"
    "$script" --help > "$out/last.log" 2>&1 || fail "$script --help"
    grep -q "usage:" "$out/last.log" || fail "$script --help gives no usage"
done

# Whole numbers: 1e4 is 10,000; 1.5 and ten are refused with a sentence.
"$leaflux" generate --leaves 1e4 --no-sky --out "$out/new/folder/tree.scene.txtpb" > "$out/gen.log"
grep -q "10000 leaves" "$out/gen.log" || fail "--leaves 1e4 did not give 10000 leaves"
refused "$leaflux" generate --leaves 1.5 --out "$out/t.scene.txtpb"
grep -q "whole number" "$out/last.log" || fail "--leaves 1.5: no sentence"
refused "$leaflux" generate --leaves ten --out "$out/t.scene.txtpb"
grep -q "whole number" "$out/last.log" || fail "--leaves ten: no sentence"

# A scene that cannot fit in memory: refused at once, with the estimate.
start=$(date +%s)
refused "$leaflux" generate --rows 1000 --columns 1000 --leaves 10000 --out "$out/huge.scene.txtpb"
grep -q "1e+10 leaves need about 40 TB of memory" "$out/last.log" || fail "no estimate"
test $(($(date +%s) - start)) -le 5 || fail "the refusal took more than 5 s"
test ! -e "$out/huge.scene.txtpb" || fail "the huge scene's file was written"

# Options the chosen kind of scene ignores are refused.
refused "$leaflux" generate --random-canopy --spacing 3 --out "$out/c.scene.txtpb"
grep -q -- "--spacing" "$out/last.log" || fail "--spacing on a random canopy: not named"
refused "$leaflux" generate --lamp-par 100 --out "$out/c.scene.txtpb"
grep -q -- "--greenhouse" "$out/last.log" || fail "--lamp-par without --greenhouse: not named"
refused "$leaflux" generate --greenhouse --sun-elevation 30 --out "$out/c.scene.txtpb"

# Output paths are checked before the solve: a folder where a file is, a file as a folder.
scene=$source/examples/scenes/leaf.scene.txtpb
touch "$out/a_file"
refused "$leaflux" solve --scene "$scene" --out "$out/a_file/leaf.csv"
grep -q "cannot be written" "$out/last.log" || fail "an unwritable --out is not named"
grep -q "receivers" "$out/last.log" && fail "the scene was read before --out was checked"
refused "$leaflux" solve --scene "$scene" --out "$out/ok.csv" --structures "$out"
grep -q -- "--structures" "$out/last.log" || fail "a folder as --structures is not named"
test ! -e "$out/ok.csv" || fail "--out was written by a solve that could not write --structures"
# Light handed down asks for structures solved whole: alone it is refused, named.
refused "$leaflux" solve --scene "$scene" --solver instanced --no-phase-db --out "$out/ok.csv" \
    --push-down
grep -q -- "--push-down" "$out/last.log" || fail "--push-down without a stop is not named"

# The solve's CSV: W and µmol columns, PAR's µmol 4.57 times its W.
"$leaflux" solve --scene "$scene" --quiet --out "$out/deep/er/leaf.csv" > "$out/solve.log"
grep -q "umol/s" "$out/solve.log" || fail "the summary has no µmol"
/usr/bin/python3 - "$out/deep/er/leaf.csv" << 'PY' || fail "the CSV's µmol columns"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
leaf = next(r for r in rows if r["organ"] == "leaf")
w, umol = float(leaf["irradiance_upper_wm2"]), float(leaf["photon_irradiance_upper_umol_m2_s"])
assert w > 100 and abs(umol - 4.57 * w) < 1e-6 * umol, (w, umol)
assert abs(float(leaf["absorbed_umol_s"]) - 4.57 * float(leaf["absorbed_w"])) < 1e-9 + 1e-6 * float(leaf["absorbed_umol_s"])
PY

# --ply holds the scene's triangles whichever solver lit them (the instanced solver's
# receivers carry none of their own).
"$leaflux" generate --leaves 40 --out "$out/t40.scene.txtpb" > /dev/null
faces() { grep -m1 "^element face" "$1" | cut -d' ' -f3; }
"$leaflux" solve --scene "$out/t40.scene.txtpb" --quiet --solver hrc --out "$out/h.csv" \
    --ply "$out/h.ply" > /dev/null
for shadows in geometry transmittance; do
    "$leaflux" solve --scene "$out/t40.scene.txtpb" --quiet --solver instanced --no-phase-db \
        --shadows "$shadows" --out "$out/i.csv" --ply "$out/i.ply" > /dev/null
    [ "$(faces "$out/i.ply")" = "$(faces "$out/h.ply")" ] && [ "$(faces "$out/h.ply")" -gt 0 ] ||
        fail "instanced --ply ($shadows): $(faces "$out/i.ply") faces, hrc $(faces "$out/h.ply")"
done

# The instanced solver writes --out as it reaches the organs when nothing after the solve
# needs their light: the CSV it writes after the solve when --ply does, nothing beside it.
"$leaflux" solve --scene "$out/t40.scene.txtpb" --quiet --solver instanced --no-phase-db \
    --shadows transmittance --out "$out/s.csv" > /dev/null
cmp -s "$out/s.csv" "$out/i.csv" || fail "instanced --out written as it goes differs from after"
[ -z "$(ls "$out" | grep partial)" ] || fail "a solve left its partial --out"

# --warm-start: an earlier --out starts the iteration (every organ found), the very file the
# solve then replaces (a growth cycle's); Monte Carlo, which has no iteration, refuses it
# naming the option.
"$leaflux" solve --scene "$out/t40.scene.txtpb" --quiet --solver hrc --out "$out/w.csv" \
    --warm-start "$out/h.csv" > "$out/warm.log"
grep -q "organs warm-started" "$out/warm.log" || fail "--warm-start: no organ started warm"
"$leaflux" solve --scene "$out/t40.scene.txtpb" --quiet --solver instanced --no-phase-db \
    --out "$out/w.csv" --warm-start "$out/w.csv" > "$out/warm.log"
grep -q "organs warm-started" "$out/warm.log" || fail "--warm-start from its own --out: none warm"
refused "$leaflux" solve --scene "$out/t40.scene.txtpb" --quiet --solver mc --out "$out/m.csv" \
    --warm-start "$out/h.csv"
grep -q -- "--warm-start" "$out/last.log" || fail "--warm-start with mc: not named"

# leaflux-grow: a sentence for a bad cycle list; a stand's options on a scenario without one.
refused "$grow" --scenario "$source/growth_stub/scenarios/stand.txtpb" --ply-cycles 2,x \
    --out "$out/grow" --endpoint tcp://127.0.0.1:9
grep -q "'x' is not a cycle number" "$out/last.log" || fail "--ply-cycles 2,x: no sentence"
grep -q "stoi" "$out/last.log" && fail "--ply-cycles 2,x: stoi"
refused "$grow" --scenario "$source/growth_stub/scenarios/wall-hole.txtpb" --spacing 2 \
    --endpoint tcp://127.0.0.1:9
grep -q "has no stand" "$out/last.log" || fail "--spacing on wall-hole was not refused"
refused "$grow" --scenario "$source/growth_stub/scenarios/stand.txtpb" --cycles 2.5 \
    --endpoint tcp://127.0.0.1:9
grep -q "whole number" "$out/last.log" || fail "--cycles 2.5: no sentence"

# client cycle --out: the cycle's light as the Python package's CSV, and a summary.
port=$((20000 + RANDOM % 20000))
endpoint=tcp://127.0.0.1:$port
"$daemon" --bind "$endpoint" 2> "$out/daemon.err" &
pids+=($!)
for _ in $(seq 50); do
    "$leaflux" client --endpoint "$endpoint" --timeout 1 status > /dev/null 2>&1 && break
    sleep 0.1
done
"$leaflux" client --endpoint "$endpoint" open --scene "$scene" > "$out/open.txt"
session=$(sed -n 's/.*session: "\([0-9a-f]*\)".*/\1/p' "$out/open.txt")
test -n "$session" || fail "no session opened: $(cat "$out/open.txt")"
"$leaflux" client --endpoint "$endpoint" cycle --session "$session" --number 1 --structures \
    --out "$out/cycle/1.csv" > "$out/cycle.txt"
grep -q "^cycle 1: 2 organs (1 of plants" "$out/cycle.txt" || fail "no summary: $(cat "$out/cycle.txt")"
grep -q "PAR: the plants absorbed" "$out/cycle.txt" || fail "the summary has no absorbed power"
test "$(wc -l < "$out/cycle.txt")" -le 4 || fail "the summary is more than a summary"
/usr/bin/python3 - "$out/cycle/1.csv" "$source/python/leaflux/results.py" << 'PY' || fail "cycle CSV"
import ast, csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
tree = ast.parse(open(sys.argv[2]).read())
columns = next(ast.literal_eval(n.value) for n in ast.walk(tree)
               if isinstance(n, ast.Assign) and getattr(n.targets[0], "id", "") == "CSV_COLUMNS")
assert list(rows[0].keys()) == columns, (list(rows[0].keys()), columns)
leaf = next(r for r in rows if r["kind"] == "organ" and r["name"] == "leaf")
assert float(leaf["irradiance_upper_wm2"]) > 100, leaf
plant = next(r for r in rows if r["kind"] == "structure" and r["type"] == "NODE_TYPE_PLANT")
assert abs(float(plant["absorbed_w"]) - float(leaf["absorbed_w"])) < 1e-9, (plant, leaf)
for r in rows:  # PAR in photons: 4.57 µmol/J times each W column
    for photons, watts in (("photon_irradiance_upper_umol_m2_s", "irradiance_upper_wm2"),
                           ("photon_irradiance_lower_umol_m2_s", "irradiance_lower_wm2"),
                           ("absorbed_umol_s", "absorbed_w")):
        assert abs(float(r[photons]) - 4.57 * float(r[watts])) <= 1e-9 * (1 + float(r[photons])), r
PY
# A band without a photon unit (NIR) has empty photon cells.
"$leaflux" generate --leaves 5 --no-sky --out "$out/two_bands.scene.txtpb" > /dev/null
"$leaflux" client --endpoint "$endpoint" open --scene "$out/two_bands.scene.txtpb" > "$out/open.txt"
session=$(sed -n 's/.*session: "\([0-9a-f]*\)".*/\1/p' "$out/open.txt")
"$leaflux" client --endpoint "$endpoint" cycle --session "$session" --number 1 \
    --out "$out/cycle/two_bands.csv" > /dev/null
/usr/bin/python3 - "$out/cycle/two_bands.csv" << 'PY' || fail "cycle CSV of PAR and NIR"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert {r["band"] for r in rows} == {"PAR", "NIR"}, rows
for r in rows:
    cells = [r["photon_irradiance_upper_umol_m2_s"], r["photon_irradiance_lower_umol_m2_s"],
             r["absorbed_umol_s"]]
    assert all(cells) if r["band"] == "PAR" else not any(cells), r
PY
echo "help defaults, whole numbers, memory estimate, ignored options, output paths, µmol" \
     "columns, leaflux-grow's checks and client cycle --out checked"
