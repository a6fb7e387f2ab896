#!/usr/bin/env bash
# The main job: generates a 2,000-leaf poplar-like tree, lights it with the Monte Carlo
# reference (PAR and NIR, sun + overcast sky) and writes per-leaf and per-structure CSVs,
# a PLY with the light on every triangle and pictures of it, then lights it again by
# hierarchical radiosity and compares; all in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release -G Ninja > /dev/null
cmake --build --preset release
out=out/demo
mkdir -p "$out"
leaflux=build/release/server/leaflux
"$leaflux" generate --leaves 2000 --seed 4 --sky-cones turtle46 --out "$out/tree.scene.txtpb"
"$leaflux" solve --scene "$out/tree.scene.txtpb" --solver mc --samples 2048 --seed 1 \
    --out "$out/leaves.csv" --structures "$out/structures.csv" --ply "$out/tree.ply" \
    | tee "$out/summary.txt"
/usr/bin/python3 examples/render_ply.py "$out/tree.ply" "$out/tree.png"
# The same tree by hierarchical radiosity, and how far it is from the reference.
"$leaflux" solve --scene "$out/tree.scene.txtpb" --solver hrc --epsilon 1e-5 \
    --out "$out/leaves_hrc.csv" | tee -a "$out/summary.txt"
/usr/bin/python3 examples/compare.py "$out/leaves.csv" "$out/leaves_hrc.csv" | tee -a "$out/summary.txt"
echo "results in $out/: leaves.csv leaves_hrc.csv structures.csv tree.ply tree.png summary.txt"
