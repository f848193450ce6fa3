#!/usr/bin/env bash
# The main job on a built-in default: installs, builds, and renders a rotation sequence of
# the built-in 3D Shepp-Logan head phantom with the image-aligned splatter, as frames in
# out/phantom/ and an animated GIF out/phantom.gif.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
build/bin/splat info synthetic:phantom:128
build/bin/splat rotate synthetic:phantom:128 --renderer sheet --tf tools/gallery/phantom-tf.json --size 384x384 \
    --elevation 20 --frames 36 -o out/phantom --gif out/phantom.gif
