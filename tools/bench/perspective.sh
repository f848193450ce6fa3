#!/usr/bin/env bash
# The splatters' perspective error against the field of view (docs/speed-vs-accuracy.md):
# X-ray of synthetic:phantom:64 at 128x128, azimuth 30, elevation 15, eye at the fitted
# distance (the bounding sphere fills the field of view); RMSE and max error relative to the
# reference's peak. Usage: bash tools/bench/perspective.sh [VOLUME] [MODE]
set -euo pipefail
cd "$(dirname "$0")/../.."
S=build/bin/splat
VOL=${1:-synthetic:phantom:64}
MODE=${2:-xray}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
common=(--mode "$MODE" --tf ct-soft --size 128x128 --azimuth 30 --elevation 15
        --projection perspective --early-termination 0)
echo "| fov | renderer | RMSE / peak | max / peak | exact pixels |"
echo "|---|---|---|---|---|"
for fov in 5 30 60 90 120 150 169.9; do
    $S render "$VOL" "${common[@]}" --fov "$fov" --renderer reference --ref-step 0.125 \
        --ref-tolerance 1e-5 -o "$tmp/ref.exr" > /dev/null
    for R in axis sheet; do
        out=$($S render "$VOL" "${common[@]}" --fov "$fov" --renderer $R -o "$tmp/$R.exr")
        exact=$(echo "$out" | grep -c "exact path" || true)
        $S compare "$tmp/$R.exr" "$tmp/ref.exr" --json "$tmp/c.json" > /dev/null
        oiiotool "$tmp/ref.exr" --printstats > "$tmp/stats.txt"
        python3 - "$tmp/c.json" "$tmp/stats.txt" "$fov" "$R" "$exact" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
line = [l for l in open(sys.argv[2]) if "Stats Max:" in l][0]
peak = max(float(x) for x in line.split(":")[1].split()[:3])
print(f"| {sys.argv[3]} | {sys.argv[4]} | {c['rmse'] / peak:.2e} | {c['max_abs'] / peak:.2e} | "
      f"{'all (eye within 3 kernel radii)' if sys.argv[5] != '0' else 'none'} |")
PY
    done
done
