#!/bin/bash
# The axis-aligned splatter's per-splat footprints against factorised sheets (n samples per
# voxel, Quality::factorisedSheets) and per-frame footprint stamps (-P phases) on ch2 (or
# VOLUME), the shared transfer function of vs_vtk.py (or TF): each setting's median CPU time
# per frame over a FRAMES-frame rotation (elevation 15), settings interleaved in rounds, its
# ratio to the per-splat frame, and each setting's RMSE against the reference ray caster on
# frames 0 and 1.
# A setting N:T adds per-splat edge tiles (--warp-tolerance T) to n = N, and the table then
# gives the tiles taken from the per-splat frame (median per frame).
# Usage: bash tools/bench/factorised_sheets.sh [BUILD] (default build; needs bench_frames).
# Environment: SIZES (default "256 512"), SETTINGS (default "0 1 2 -16"), ROUNDS (default 2),
# FRAMES (default 6), VOLUME (default ch2; any volume argument, e.g. synthetic:phantom:512),
# TF (a transfer function for --tf; default the benchmark's), EXTRA (more render options for
# every renderer, e.g. "--early-termination 0").
set -euo pipefail
BIN=${1:-build}/bin/bench_frames
VOLUME=${VOLUME:-/usr/share/mricron/templates/ch2.nii.gz}
[ -x "$BIN" ] || { echo "factorised_sheets: $BIN is missing" >&2; exit 1; }
case "$VOLUME" in synthetic:*) ;; *)
    [ -f "$VOLUME" ] || { echo "factorised_sheets: $VOLUME is missing (ch2: Debian package mricron-data)" >&2; exit 77; } ;;
esac
OUT=$(mktemp -d /tmp/factorised_sheets.XXXXXX)
trap 'rm -rf "$OUT"' EXIT
BENCH_TF=$OUT/tf.json
TF=${TF:-$BENCH_TF}
FRAMES=${FRAMES:-6}
read -r -a EXTRA_ARGS <<< "${EXTRA:-}"
cat > "$BENCH_TF" <<'JSON'
{"domain": "normalized", "unit_distance": 1.0, "points": [[0.0, 0.0, 0.0, 0.0, 0.0], [0.25, 0.45, 0.3, 0.25, 0.0], [0.5, 0.9, 0.6, 0.5, 0.3], [1.0, 1.0, 1.0, 1.0, 0.8]]}
JSON
SIZES=${SIZES:-"256 512"}
SETTINGS=${SETTINGS:-"0 1 2 -16"}
ROUNDS=${ROUNDS:-2}
for S in $SIZES; do
    mkdir -p "$OUT/${S}_ref"
    nice "$BIN" render "$VOLUME" "$TF" --renderer reference --size "$S" --frames "$FRAMES" \
        --save 0,1 --out "$OUT/${S}_ref" "${EXTRA_ARGS[@]}" > /dev/null 2>&1
    for r in $(seq 1 "$ROUNDS"); do
        for N in $SETTINGS; do
            mkdir -p "$OUT/${S}_$N"
            edges=()
            case "$N" in *:*) edges=(--warp-tolerance "${N#*:}") ;; esac
            nice "$BIN" render "$VOLUME" "$TF" --renderer axis --size "$S" --frames "$FRAMES" \
                --factorised-sheets="${N%%:*}" "${edges[@]}" --save 0,1 --out "$OUT/${S}_$N" \
                "${EXTRA_ARGS[@]}" > "$OUT/${S}_${N}_r$r.json"
        done
    done
done
/usr/bin/python3 - "$OUT" "$BIN" "$SIZES" "$SETTINGS" <<'PY'
import glob, json, statistics, subprocess, sys
out, binary, sizes, settings = sys.argv[1], sys.argv[2], sys.argv[3].split(), sys.argv[4].split()
for s in sizes:
    base = None
    for n in settings:
        frames = [f for p in glob.glob(f"{out}/{s}_{n}_r*.json") for f in json.load(open(p))["frames"]]
        med = statistics.median(f["cpu_ms"] for f in frames)
        tiles = statistics.median(f.get("warp_fix_tiles", 0) for f in frames)
        base = base or med
        errs = [json.loads(subprocess.check_output(
            [binary, "compare", f"{out}/{s}_{n}/frame_{k}.f32", f"{out}/{s}_ref/frame_{k}.f32",
             s, s]))["rmse"] for k in (0, 1)]
        print(f"{s}^2 setting {n:>4}: CPU {med:6.1f} ms per frame, {med / base:.2f}x per-splat; "
              f"RMSE vs reference {errs[0]:.2e} {errs[1]:.2e}"
              + (f"; edge tiles {tiles:g}" if ":" in n else ""))
PY
