#!/usr/bin/env bash
# examples/foreign_growth.py grows a plausible rosette: 12 leaves (a leaf a day) make
# 0.02–0.2 m² of leaves (a lettuce of 12 leaves: about 0.05–0.1 m²), never more than 12
# grown leaves, and every cycle adds leaf area and dry matter.
# Usage: foreign_growth_check.sh SOURCE_DIR   (LEAFLUX_BUILD: the build's folder)
set -euo pipefail
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
/usr/bin/python3 "$1/examples/foreign_growth.py" --cycles 12 --csv "$out/rosette.csv"
awk -F, '
    NR > 1 && ($3 <= area || $5 <= biomass) { print "cycle " $1 ": no growth"; bad = 1 }
    { area = $3; biomass = $5; leaves = $2 }
    END {
        if (leaves != 12) { print "leaves: " leaves; bad = 1 }
        if (area < 0.02 || area > 0.2) { print "rosette of " area " m² from 12 leaves"; bad = 1 }
        if (area > 12 * 0.012) { print "larger than 12 grown leaves"; bad = 1 }
        printf "rosette: %.4f m², %.2f g after %d leaves\n", area, biomass, leaves
        exit bad
    }' "$out/rosette.csv"
