#!/usr/bin/env bash
# The pictures of docs/accuracy.md "Aliasing and EWA": an X-ray of synthetic:phantom:128 at
# 128x128 (a voxel covers 0.58 pixels), axis-aligned splatter without and with EWA, the
# pixel-filtered reference (Gaussian, sigma 0.5 pixels), and |splatter - filtered reference|.
# Usage: bash tools/gallery_ewa.sh   (after tools/build.sh; tools/gallery.sh runs it too)
set -euo pipefail
cd "$(dirname "$0")/.."
S=build/bin/splat
G=tools/gallery
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
V=synthetic:phantom:128
A=(--mode xray --azimuth 30 --elevation 20 --size 128x128)
$S render $V "${A[@]}" --ewa off -o $tmp/off.exr
$S render $V "${A[@]}" --ewa on -o $tmp/on.exr
$S render $V "${A[@]}" --renderer reference --pixel-filter 0.5 -o $tmp/filtered.exr
# One display window for the three (the line integral, world units): [60, 115], where the
# phantom's inner ellipsoids show.
for n in off on filtered; do
    oiiotool $tmp/$n.exr --ch R,G,B --subc 60 --mulc 0.018182 --clamp:min=0:max=1 -d uint8 -o $G/aliasing_$n.png
done
$S compare $tmp/off.exr $tmp/filtered.exr --heatmap $G/aliasing_error_off.png --scale 2
$S compare $tmp/on.exr $tmp/filtered.exr --heatmap $G/aliasing_error_on.png --scale 2
