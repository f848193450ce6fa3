#!/bin/bash
# The image-aligned splatter (--renderer sheet) of two builds against the axis-aligned splatter
# on ch2 with the mri-head preset, THREADS threads, a 3-frame rotation (elevation 15, one warm-up
# frame): per setting, CPU time (user + sys) and wall time per frame, averaged over rounds that
# interleave A's sheet, B's sheet and A's axis-aligned frame, B's and the axis ratio to A's sheet.
# Usage: bash tools/bench/sheet_vs_axis.sh A_BENCH_FRAMES B_BENCH_FRAMES
# Environment: SIZES (default "512 256"), SLABS (default "1 0.5"), ROUNDS (default 3), THREADS
# (default 2).
set -euo pipefail
A=${1:?usage: sheet_vs_axis.sh A_BENCH_FRAMES B_BENCH_FRAMES}
B=${2:?usage: sheet_vs_axis.sh A_BENCH_FRAMES B_BENCH_FRAMES}
CH2=/usr/share/mricron/templates/ch2.nii.gz
for bin in "$A" "$B"; do [ -x "$bin" ] || { echo "sheet_vs_axis: $bin is missing" >&2; exit 1; }; done
[ -f "$CH2" ] || { echo "sheet_vs_axis: $CH2 is missing (Debian package mricron-data)" >&2; exit 77; }
OUT=$(mktemp -d /tmp/sheet_vs_axis.XXXXXX)  # the per-run JSON of bench_frames
trap 'rm -rf "$OUT"' EXIT
SIZES=${SIZES:-"512 256"}
SLABS=${SLABS:-"1 0.5"}
ROUNDS=${ROUNDS:-3}
THREADS=${THREADS:-2}
for r in $(seq 1 "$ROUNDS"); do
    for S in $SIZES; do
        for T in $SLABS; do
            for run in "A sheet $A" "B sheet $B" "A axis $A"; do
                set -- $run
                slab=(--slab "$T")
                [ "$2" = axis ] && slab=()  # the axis-aligned splatter has no slabs
                nice "$3" render "$CH2" mri-head --renderer "$2" "${slab[@]}" --size "$S" \
                    --threads "$THREADS" --frames 3 --warmup 1 > "$OUT/${1}_${2}_${S}_${T}_r$r.json"
            done
        done
    done
done
/usr/bin/python3 - "$OUT" "$SIZES" "$SLABS" <<'PY'
import glob, json, sys
out, sizes, slabs = sys.argv[1], sys.argv[2].split(), sys.argv[3].split()
def mean(tag, key):
    v = [f[key] for p in glob.glob(f"{out}/{tag}_r*.json") for f in json.load(open(p))["frames"]]
    return sum(v) / len(v)
for s in sizes:
    for t in slabs:
        a, b, x = (f"A_sheet_{s}_{t}", f"B_sheet_{s}_{t}", f"A_axis_{s}_{t}")
        ca, cb, cx = (mean(k, "cpu_ms") for k in (a, b, x))
        wa, wb, wx = (mean(k, "ms") for k in (a, b, x))
        print(f"{s}^2 slab {t}: CPU ms A sheet {ca:.0f}, B sheet {cb:.0f} ({cb / ca:.2f}x A), "
              f"axis {cx:.0f} (B / axis {cb / cx:.2f}x, A / axis {ca / cx:.2f}x); wall ms "
              f"{wa:.0f}, {wb:.0f} ({wb / wa:.2f}x), {wx:.0f} (B / axis {wb / wx:.2f}x)")
PY
