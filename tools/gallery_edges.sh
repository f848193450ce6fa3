#!/usr/bin/env bash
# The pictures of docs/speed-vs-accuracy.md "Factorised sheets with per-splat edge tiles":
# synthetic:phantom:128 with tools/gallery/phantom-tf.json at 256x256 (azimuth 30, elevation
# 15), factorised sheets
# at two samples per voxel with --warp-tolerance 0.01, the tiles it took from the per-splat
# frame outlined (the tiles where its frame differs from the warp alone, --warp-tolerance 1),
# and |frame - reference| without and with the edge tiles, on one scale.
# Usage: bash tools/gallery_edges.sh   (after tools/build.sh; tools/gallery.sh runs it too)
set -euo pipefail
cd "$(dirname "$0")/.."
S=build/bin/splat
B=build/bin/bench_frames
G=tools/gallery
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
V=synthetic:phantom:128
TF=tools/gallery/phantom-tf.json
A=(--tf $TF --size 256x256 --azimuth 30 --elevation 15)
$S render $V "${A[@]}" --warp-tolerance 0.01 -o $tmp/edges.exr
$S render $V "${A[@]}" --warp-tolerance 0.01 -o $tmp/edges.png
$S render $V "${A[@]}" --warp-tolerance 1 -o $tmp/warp.exr
$S render $V "${A[@]}" --renderer reference -o $tmp/reference.exr
# The tiles (32 pixels, the default --tile-size) where the two frames differ: frame 1 of a
# 12-frame rotation is azimuth 30.
for t in 0.01 1; do
    mkdir -p $tmp/f$t
    $B render $V $TF --renderer axis --size 256 --frames 12 --elevation 15 --warmup 0 \
        --warp-tolerance $t --save 1 --out $tmp/f$t > /dev/null
done
boxes=$(/usr/bin/python3 - $tmp/f0.01/frame_1.f32 $tmp/f1/frame_1.f32 <<'PY'
import sys
import numpy as np
a, b = (np.fromfile(p, np.float32).reshape(256, 256, 4) for p in sys.argv[1:3])
differ = np.any(a != b, axis=2).reshape(8, 32, 8, 32).any(axis=(1, 3))
print(" ".join(f"--box:color=1,0.85,0:fill=0 {32 * x},{32 * y},{32 * x + 31},{32 * y + 31}"
               for y, x in zip(*np.nonzero(differ))))
PY
)
# shellcheck disable=SC2086  # one argument per word
oiiotool $tmp/edges.png $boxes -o $G/edge_tiles.png
# One scale for both heat maps: a quarter of the warp's largest error.
scale=$($S compare $tmp/warp.exr $tmp/reference.exr | awk '/^max abs/ {print $3 / 4}')
$S compare $tmp/warp.exr $tmp/reference.exr --heatmap $G/edge_error_warp.png --scale "$scale"
$S compare $tmp/edges.exr $tmp/reference.exr --heatmap $G/edge_error_tiles.png --scale "$scale"
