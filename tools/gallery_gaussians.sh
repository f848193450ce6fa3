#!/usr/bin/env bash
# The pictures and reports of docs/gaussians.md "Popping in Gaussian scenes":
#  - the four Gaussian renderers on the same two views of gaussians:pop (azimuth -2 and +2, on
#    both sides of the swap of the two centres' depths at 0), 96 x 96;
#  - the four renderers on ch2 as Gaussians (`splat gaussians` of the ch2 template sampled every
#    3 mm, so that the sheets and the reference stay fast), azimuth 30, 128 x 128;
#  - the popping reports of both scenes (the printed summaries are quoted in the doc).
# Usage: bash tools/gallery_gaussians.sh [REPORT_DIR]   (after tools/build.sh; needs python3-nibabel)
set -euo pipefail
cd "$(dirname "$0")/.."
S=build/bin/splat
G=splat/docs/images
R=${1:-build/gaussian_reports}
mkdir -p $G $R
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# gaussians:pop: red at x = -0.6, blue at x = +0.6, their depths swap at azimuth 0.
for r in 3dgs 3dgs-pixel sheet reference; do
    for a in -2 2; do
        $S render gaussians:pop --renderer $r --azimuth $a --size 96x96 --slab 0.05 \
            --ref-tolerance 1e-5 -o $G/gaussians_pop_${r}_az$a.png > /dev/null
    done
done
$S popping gaussians:pop --from -5.5 --to 5.5 --step 1 --size 64x64 --slab 0.05 \
    --ref-tolerance 1e-5 --refine 8 -q --report $R/pop | tee $R/pop.txt

# ch2 (1 mm MNI template) every 3 mm: one Gaussian per visible voxel of the mri-head preset.
/usr/bin/python3 - "$tmp/ch2_3mm.nii.gz" <<'PY'
import sys
import nibabel as nib
import numpy as np
img = nib.load("/usr/share/mricron/templates/ch2.nii.gz")
data = np.asanyarray(img.dataobj)[::3, ::3, ::3]
affine = img.affine.copy()
affine[:3, :3] *= 3
nib.save(nib.Nifti1Image(data, affine, img.header), sys.argv[1])
PY
$S gaussians $tmp/ch2_3mm.nii.gz --tf mri-head -o $tmp/ch2.ply
for r in 3dgs 3dgs-pixel sheet reference; do
    $S render $tmp/ch2.ply --renderer $r --azimuth 30 --size 128x128 --threads 2 \
        -o $G/gaussians_ch2_$r.png > /dev/null
done
$S popping $tmp/ch2.ply --from 25 --to 29 --step 1 --size 64x64 --refine 4 --threads 2 -q \
    --report $R/ch2 | tee $R/ch2.txt
