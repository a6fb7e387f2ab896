#!/usr/bin/env bash
# Interleaved solve times of two builds on one scene, for a change that must not slow the
# solver: runs A and B alternately RUNS times each and prints each build's times, mean and
# median (seconds, from the solver's own summary line); appends them to OUT.csv if given.
#   scripts/compare_builds.sh A/leaflux B/leaflux SCENE.scene.txtpb SOLVER_ARGS RUNS [OUT.csv]
# e.g. scripts/compare_builds.sh ../old/build/release/server/leaflux \
#      build/release/server/leaflux canopy500.scene.txtpb "--solver hrc --epsilon 3e-4" 7
set -euo pipefail
a=$1 b=$2 scene=$3 args=$4 runs=$5 out=${6:-}
tmp=$(mktemp)
for _ in $(seq "$runs"); do
    for build in "$a" "$b"; do
        # shellcheck disable=SC2086
        t=$("$build" solve --scene "$scene" $args --out /dev/null 2>&1 |
            sed -n 's/.* in \([0-9.e+-]*\) s .*/\1/p')
        echo "$build,$t" >> "$tmp"
    done
done
for build in "$a" "$b"; do
    # The build's own lines: one build's path may hold the other's.
    awk -F, -v build="$build" '$1 == build { print $2 }' "$tmp" | sort -g | awk -v build="$build" -v scene="$scene" \
        -v args="$args" -v out="$out" '
        { t[NR] = $1; s += $1 }
        END {
            median = NR % 2 ? t[(NR + 1) / 2] : (t[NR / 2] + t[NR / 2 + 1]) / 2
            printf "%s  mean %.3f s  median %.3f s  (%d runs)\n", build, s / NR, median, NR
            if (out != "") printf "%s,%s,%s,%d,%.4f,%.4f\n", scene, args, build, NR, s / NR, median >> out
        }'
done
rm -f "$tmp"
