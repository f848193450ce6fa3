#!/usr/bin/env bash
# The README's performance table: ms per frame (median of repeats) of both splatters on
# ch2 (mri-head) and synthetic:phantom:256 (ct-bone) at 512x512, for 1 and 2 threads.
# Usage: bash tools/bench.sh [REPEATS]   (after tools/build.sh; takes several minutes)
set -euo pipefail
cd "$(dirname "$0")/.."
S=build/bin/splat
R=${1:-3}
out=$(mktemp -d)
row() {  # name volume tf renderer slab threads
    $S bench "$2" --tf "$3" --renderer "$4" --slab "$5" --size 512x512 --repeats "$R" \
        --thread-list "$6" --json "$out/r.json" > /dev/null
    python3 - "$1" "$4" "$5" "$out/r.json" <<'PY'
import json, sys
name, renderer, slab, path = sys.argv[1:]
d = json.load(open(path))
for r in d["runs"]:
    label = renderer if renderer == "axis" else f"{renderer} (slab {slab})"
    print(f"| {name} | {label} | {r['threads']} | {r['median_ms']:.0f} | {r['splats']} | "
          f"{r['footprint_pixels'] / 1e6:.1f} M | {r['footprint_pixels_per_s'] / 1e6:.0f} M/s |")
PY
}
echo "| volume | renderer | threads | ms/frame | splats | footprint px | footprint px/s |"
echo "|---|---|---|---|---|---|---|"
for v in "ch2|/usr/share/mricron/templates/ch2.nii.gz|mri-head" "phantom:256|synthetic:phantom:256|ct-bone"; do
    IFS='|' read -r name vol tf <<< "$v"
    row "$name" "$vol" "$tf" axis 1 1,2
    for slab in 1 0.5 0.25; do row "$name" "$vol" "$tf" sheet $slab 1,2; done
done
