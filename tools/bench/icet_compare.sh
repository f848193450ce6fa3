#!/usr/bin/env bash
# splat's direct-send compositing beside IceT's (docs/parallel.md "Memory, scaling and a model"):
# builds tools/bench/icet/icet_compare and runs it under `mpirun --oversubscribe -np P` for P = 2,
# 3, 4, 8 at 256^2, 512^2 and 1024^2, then prints a markdown table (median time of the slowest rank,
# bytes sent per rank, max abs against a one-process composite). Exits 77 when IceT is not installed
# (Debian: paraview-dev). Usage: bash tools/bench/icet_compare.sh [REPS] [RANKS] [SIZES] [IMAGES]
#   (defaults 15, "2 3 4 8", "256 512 1024", 0.7; after tools/build.sh). IMAGES is either a
#   number, the diameter of each rank's synthetic disc over the image side (0.7 leaves 62%
#   of every partial image transparent, 3 covers it all: no transparent pixel for IceT's
#   run-length encoding), or a volume (e.g. synthetic:phantom:128) whose bricked render
#   gives the partial images (rank 0 renders P bricks, axis splatter, gray-ramp).
# ICET_COMPARE_BASE=PATH also runs another build's icet_compare (e.g. one built from the
# commit before the sparse direct-send) right after this one for each P and size, its
# methods marked "(base)", so old and new are measured interleaved.
set -euo pipefail
cd "$(dirname "$0")/../.."
REPS=${1:-15}
RANKS=${2:-"2 3 4 8"}
SIZES=${3:-"256 512 1024"}
IMAGES=${4:-0.7}
if [[ "$IMAGES" =~ ^[0-9.]+$ ]]; then images=(--coverage "$IMAGES"); else images=(--volume "$IMAGES"); fi
[ -f build/CMakeCache.txt ] || { echo "icet_compare: run tools/build.sh first" >&2; exit 1; }
cmake -S . -B build > /dev/null
if ! grep -q '^SPLAT_ICET_CORE:FILEPATH=/' build/CMakeCache.txt ||
    ! grep -q '^SPLAT_ICET_INCLUDE_DIR:PATH=/' build/CMakeCache.txt; then
    echo "icet_compare: IceT not found (Debian: apt-get install paraview-dev); skipped" >&2
    exit 77
fi
cmake --build build -j2 --target icet_compare > /dev/null
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl=self,vader OMPI_MCA_btl_vader_single_copy_mechanism=none
out=build/icet_compare.jsonl
echo "(partial images: ${images[*]})"
: > "$out"
for p in $RANKS; do
    for n in $SIZES; do
        mpirun --oversubscribe -np "$p" build/bin/icet_compare --size "$n" --reps "$REPS" "${images[@]}" >> "$out"
        if [ -n "${ICET_COMPARE_BASE:-}" ]; then
            mpirun --oversubscribe -np "$p" "$ICET_COMPARE_BASE" --size "$n" --reps "$REPS" "${images[@]}" |
                sed 's/"method": "\([^"]*\)"/"method": "\1 (base)"/' >> "$out"
        fi
    done
done
/usr/bin/python3 - "$out" <<'PY'
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
print("| P | image | method | median ms | bytes sent per rank (max / mean) | max abs vs one process |")
print("|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['P']} | {r['size']}² | {r['method']} | {r['median_ms']:.2f} | "
          f"{r['bytes_sent_max']:,.0f} / {r['bytes_sent_mean']:,.0f} | {r['max_abs']:.2g} |")
PY
echo "(raw: $out)"
