#!/usr/bin/env bash
# The main job on a built-in default: installs, builds, and renders a rotation sequence of
# the built-in 3D Shepp-Logan head phantom with the image-aligned splatter, as frames in
# out/phantom/ and an animated GIF out/phantom.gif, and analyses where the axis-aligned
# splatter pops against the image-aligned one and the reference: out/popping/report.html.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
build/bin/splat info synthetic:phantom:128
build/bin/splat rotate synthetic:phantom:128 --renderer sheet --tf tools/gallery/phantom-tf.json --size 384x384 \
    --elevation 20 --frames 36 -o out/phantom --overwrite --gif out/phantom.gif \
    --contact-sheet out/phantom_sheet.png
build/bin/splat popping synthetic:phantom:64 --tf ct-soft --size 128x128 --from 40 --to 50 --step 0.5 \
    --report out/popping
