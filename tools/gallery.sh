#!/usr/bin/env bash
# Renders the README's pictures into tools/gallery/ with the project's own renderer.
# Usage: bash tools/gallery.sh   (after tools/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
S=build/bin/splat
G=tools/gallery
CH2=/usr/share/mricron/templates/ch2.nii.gz
mkdir -p "$G"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# A real MRI head (ch2, 181x217x181, 1 mm), shaded, seen from the front.
$S render $CH2 --tf mri-head --shade --azimuth 180 --elevation 10 --size 400x400 -o $G/head_axis.png
# The popping angle: 45 degrees, axis-aligned vs image-aligned sheets.
$S render $CH2 --tf mri-head --shade --azimuth 135 --elevation 10 --size 320x320 --renderer axis -o $G/head_axis_45.png
$S render $CH2 --tf mri-head --shade --azimuth 135 --elevation 10 --size 320x320 --renderer sheet -o $G/head_sheet_45.png
# MIP and X-ray of the same head.
$S render $CH2 --mode mip --azimuth 90 --size 320x320 -o $G/head_mip.png
$S render $CH2 --mode xray --azimuth 90 --size 320x320 -o $G/head_xray.png
# The built-in 3D Shepp-Logan phantom, image-aligned, post-classified.
$S render synthetic:phantom:128 --tf tools/gallery/phantom-tf.json --renderer sheet --elevation 25 --azimuth 30 --size 320x320 -o $G/phantom_sheet.png
$S render synthetic:phantom:128 --tf tools/gallery/phantom-tf.json --renderer sheet --classify post --elevation 25 --azimuth 30 --size 320x320 -o $G/phantom_sheet_post.png
# One kernel's footprint (X-ray of a single voxel), isotropic and with spacing 1 x 1 x 3.
python3 -c "import struct,sys; sys.stdout.buffer.write(struct.pack('<f', 1.0))" > $tmp/one_1x1x1_float32.raw
$S render $tmp/one_1x1x1_float32.raw --mode xray --pixel-size 0.04 --size 160x160 -o $G/footprint.png
$S render $tmp/one_1x1x1_float32.raw --spacing 1,1,3 --mode xray --azimuth 30 --elevation 40 --pixel-size 0.06 --size 160x160 -o $G/footprint_elliptical.png
# Error against the reference ray caster at 45 degrees (phantom:64, 256x256).
for r in axis sheet reference; do
    $S render synthetic:phantom:64 --tf ct-soft --azimuth 45 --size 256x256 --early-termination 0 --renderer $r -o $tmp/$r.exr
done
$S compare $tmp/axis.exr $tmp/reference.exr --heatmap $G/error_axis_45.png --scale 0.05
$S compare $tmp/sheet.exr $tmp/reference.exr --heatmap $G/error_sheet_45.png --scale 0.05
$S render synthetic:phantom:64 --tf ct-soft --azimuth 45 --size 256x256 --renderer reference -o $G/phantom_reference_45.png
# A small rotation of the phantom as an animated GIF.
$S rotate synthetic:phantom:96 --tf tools/gallery/phantom-tf.json --renderer sheet --elevation 20 --size 192x192 --frames 24 -o $tmp/frames --gif $G/phantom_rotate.gif
# Popping: where the axis-aligned splatter's sheets turn (ch2, mri-head, 40..50 degrees): the
# error-jump plot and the event's frames before/after with their differences.
$S popping $CH2 --tf mri-head --size 128x128 --from 40 --to 50 --step 0.5 --report $tmp/popping -q
python3 tools/popping_figures.py $tmp/popping $G/popping_ch2
