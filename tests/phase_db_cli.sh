#!/usr/bin/env bash
# `leaflux phase-db` as users run it: stats, list, export of a function to CSV (into a new
# folder too), verify of a sound and of a damaged file, compact, and refusal of a file that
# is not a phase database.
# Usage: phase_db_cli.sh BUILD_DIR
set -euo pipefail
build=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
leaflux=$build/server/leaflux
db=$out/phase.db
fail() { echo "FAIL: $1"; exit 1; }

# A few rows: the writer's first is a 130² × 2 bi-directional function, then mono ones.
timeout 0.5 "$build/tests/leaflux_phase_db_writer" "$db" 1 > "$out/keys" || true
rows=$(wc -l < "$out/keys")
[ "$rows" -ge 2 ] || fail "the writer committed $rows rows"

"$leaflux" phase-db --help | grep -q "export" || fail "no export in --help"
"$leaflux" phase-db stats --db "$db" | grep -q "schema version  1" || fail "stats"
[ "$("$leaflux" phase-db list --db "$db" --keys | wc -l)" -ge "$rows" ] || fail "list --keys"
"$leaflux" phase-db verify --db "$db" | grep -q "0 bad: sound" || fail "verify of a sound file"

# Row 1, bi-directional at 130 directions and 2 bands: a header, τ, then f.
"$leaflux" phase-db export --db "$db" --id 1 --out "$out/f.csv" 2> /dev/null
[ "$(grep -c '^tau,' "$out/f.csv")" -eq 130 ] || fail "τ rows"
[ "$(grep -c '^f,' "$out/f.csv")" -eq $((130 * 130 * 2)) ] || fail "f rows"
"$leaflux" phase-db export --db "$db" --key "$(head -1 "$out/keys")" | cmp -s - "$out/f.csv" ||
    fail "export by key differs from export by id"
# Its folder is made, as every --out's.
"$leaflux" phase-db export --db "$db" --id 1 --out "$out/new/folder/f.csv" 2> /dev/null
cmp -s "$out/new/folder/f.csv" "$out/f.csv" || fail "export into a new folder"

# A damaged row: verify names it and fails, export refuses it.
/usr/bin/python3 - "$db" << 'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
blob = bytearray(db.execute("SELECT blob FROM phase_functions WHERE id = 2").fetchone()[0])
blob[60] ^= 0xFF
db.execute("UPDATE phase_functions SET blob = ? WHERE id = 2", (bytes(blob),))
db.commit()
PY
if "$leaflux" phase-db verify --db "$db" > "$out/verify"; then fail "verify passed a damaged row"; fi
grep -q "bad row 2" "$out/verify" || fail "verify did not name row 2"
if "$leaflux" phase-db export --db "$db" --id 2 > /dev/null 2>&1; then fail "exported a bad row"; fi
"$leaflux" phase-db compact --db "$db" | grep -q "after" || fail "compact"

# Not a phase database: refused, left as it was.
printf 'not a database\n%.0s' $(seq 20) > "$out/notes.txt"
cp "$out/notes.txt" "$out/notes.copy"
if "$leaflux" phase-db stats --db "$out/notes.txt" > "$out/err" 2>&1; then fail "opened a text file"; fi
grep -q "notes.txt" "$out/err" || fail "the error does not name the file"
cmp -s "$out/notes.txt" "$out/notes.copy" || fail "the text file was changed"
if "$leaflux" phase-db stats --db "$out/missing.db" > /dev/null 2>&1; then fail "opened a missing file"; fi
[ ! -e "$out/missing.db" ] || fail "an inspection created a file"
echo PASS
