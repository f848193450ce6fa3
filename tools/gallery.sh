#!/usr/bin/env bash
# Renders the pictures of README.md and splat/docs/ into tools/gallery/ with the project's own
# renderer.
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
/usr/bin/python3 -c "import struct,sys; sys.stdout.buffer.write(struct.pack('<f', 1.0))" > $tmp/one_1x1x1_float32.raw
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
/usr/bin/python3 tools/popping_figures.py $tmp/popping $G/popping_ch2

# ---- Techniques: shading, edges, isosurfaces, labels, clipping, views ----------
T=/usr/share/mricron/templates
# Post-classified ch2, unshaded and shaded (Blinn-Phong, light from the upper left).
$S render $CH2 --tf mri-head --classify post --renderer sheet --azimuth 180 --elevation 10 --size 320x320 -o $G/tech_head_post.png
$S render $CH2 --tf mri-head --classify post --renderer sheet --azimuth 180 --elevation 10 --size 320x320 --shade --light -1,-1,1 -o $G/tech_head_post_shaded.png
# Edge enhancement (opacity x |grad d| / max): boundaries stand out in the low-contrast MRI;
# the same view without it beside.
$S render $CH2 --tf mri-head --azimuth 90 --size 320x320 -o $G/tech_head_noedges.png
$S render $CH2 --tf mri-head --azimuth 90 --size 320x320 --edges 1 -o $G/tech_head_edges.png
# An isosurface of the phantom from each renderer.
for r in axis sheet reference; do
    $S render synthetic:phantom:96 --mode iso --iso-level 0.5 --iso-normalized --renderer $r --azimuth 30 --elevation 20 --size 256x256 --shade -o $G/tech_iso_$r.png
done
# ch2 with the AAL atlas (116 regions, mricron's colours), and a selection of regions.
$S render $CH2 --tf mri-head --label-volume $T/aal.nii.gz --label-colors $T/aal.nii.lut --label-names $T/aal.nii.txt --labels 37,38,41,42 --azimuth 135 --elevation 20 --size 320x320 --renderer sheet -o $G/tech_ch2_aal.png
$S render $T/aal.nii.gz --label-colors $T/aal.nii.lut --azimuth 135 --elevation 20 --size 320x320 -o $G/tech_aal.png
# A clipped head: the field is cut at the midsagittal plane (x = 0), so the cut face, turned
# towards the camera, shows the data there.
$S render $CH2 --tf mri-head --shade --azimuth 120 --elevation 15 --size 320x320 --clip-plane 0,0,0,1,0,0 -o $G/tech_head_clipped.png
# An isosurface cut by a plane facing the camera: capped at the cut.
$S render synthetic:phantom:96 --mode iso --iso-level 0.5 --iso-normalized --renderer sheet --azimuth 30 --elevation 20 --size 256x256 --shade --clip-plane 47.5,47.5,47.5,0.47,-0.81,0.34 -o $G/tech_iso_clipped.png
# Volume viewing through the reconstructed field: slices, an oblique MPR and a CPR.
$S slices $CH2 --axis z --every 12 --scale-bar 50 -o $tmp/slices && cp $tmp/slices/mosaic.png $G/tech_slices_mosaic.png
$S mpr $CH2 --plane 0,0,10,0.3,0.2,1 --size 256x256 --pixel-size 0.8 --scale-bar 50 -o $G/tech_mpr_oblique.png
printf '{"points": [[-60, -20, 10], [-30, 40, 20], [30, 40, 20], [60, -20, 10]], "lateral": [0, 0, 1], "width": 160}\n' > $tmp/curve.json
$S cpr $CH2 --curve $tmp/curve.json -o $G/tech_cpr.png
# CT in Hounsfield units: the Shepp-Logan head in HU (air -1000, b = -1000), the
# CT look chosen from the data (no --tf: ct-hu), cut open at x = 63.5; post-classified; MIP.
$S render synthetic:ct-phantom:128 --azimuth 120 --elevation 15 --size 320x320 --clip-plane 63.5,0,0,1,0,0 --shade -o $G/ct_hu_clipped.png
$S render synthetic:ct-phantom:128 --classify post --azimuth 120 --elevation 15 --size 320x320 --clip-plane 63.5,0,0,1,0,0 -o $G/ct_hu_post.png
$S render synthetic:ct-phantom:128 --mode mip --azimuth 90 --size 320x320 -o $G/ct_hu_mip.png
# Aliasing with and without EWA (docs/accuracy.md "Aliasing and EWA").
bash tools/gallery_ewa.sh
bash tools/gallery_edges.sh
