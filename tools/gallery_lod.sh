#!/usr/bin/env bash
# The pictures of docs/speed-vs-accuracy.md "Level of detail": an X-ray of synthetic:phantom:128 at
# 64x64 (a voxel covers 0.29 pixels): the axis-aligned splatter at full resolution, at --lod 1
# (which takes level 2 here, the doubled kernel), at --lod auto (level 1, the merged footprint
# narrowed to k^2 - B_1 + sigma^2), the pixel-filtered reference (sigma 0.5 pixels), and
# |splatter - filtered reference| (heat maps scaled to 2).
# Usage: bash tools/gallery_lod.sh   (after tools/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
S=build/bin/splat
G=tools/gallery
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
V=synthetic:phantom:128
A=(--mode xray --azimuth 30 --elevation 20 --size 64x64)
$S render $V "${A[@]}" --lod 0 -o $tmp/full.exr
$S render $V "${A[@]}" --lod 1 -o $tmp/lod1.exr
$S render $V "${A[@]}" --lod auto -o $tmp/auto.exr
$S render $V "${A[@]}" --renderer reference --pixel-filter 0.5 -o $tmp/filtered.exr
# The display window of gallery_ewa.sh: [60, 115] (the line integral, world units).
for n in full lod1 auto filtered; do
    oiiotool $tmp/$n.exr --ch R,G,B --subc 60 --mulc 0.018182 --clamp:min=0:max=1 -d uint8 -o $G/lod_$n.png
done
for n in full lod1 auto; do
    $S compare $tmp/$n.exr $tmp/filtered.exr --heatmap $G/lod_error_$n.png --scale 2
done
