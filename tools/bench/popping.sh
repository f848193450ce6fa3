#!/usr/bin/env bash
# The popping analyzer's cost (docs/popping.md): a 21-angle azimuth sweep
# (40..50 degrees in 0.5 degree steps) of ch2 with mri-head at 256x256, once with all three
# renderers and once without the reference, refinement off (the sweep alone) and on.
# Usage: bash tools/bench/popping.sh [THREADS]   (after tools/build.sh; takes a few minutes)
set -euo pipefail
cd "$(dirname "$0")/../.."
S=build/bin/splat
T=${1:-2}
CH2=/usr/share/mricron/templates/ch2.nii.gz
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
run() {  # label renderers refine
    local start end
    start=$(date +%s.%N)
    $S popping $CH2 --tf mri-head --size 256x256 --from 40 --to 50 --step 0.5 --threads "$T" \
        --renderers "$2" --refine "$3" --report "$tmp/r" -q > "$tmp/out.txt"
    end=$(date +%s.%N)
    python3 - "$1" "$3" "$start" "$end" "$tmp/out.txt" <<'PY'
import sys
label, refine, start, end, path = sys.argv[1:]
rows = [l.split() for l in open(path) if l.split() and l.split()[0] in ("axis", "sheet", "reference")]
per = ", ".join(f"{r[0]} {float(r[5]):.0f} ms" for r in rows)
print(f"| {label} | {refine} | {float(end) - float(start):.1f} s | {per} |")
PY
}
echo "| renderers | refine levels | wall time | median ms per frame |"
echo "|---|---|---|---|"
run "axis, sheet, reference" axis,sheet,reference 0
run "axis, sheet" axis,sheet 0
run "axis, sheet, reference" axis,sheet,reference 10
run "axis, sheet" axis,sheet 10
