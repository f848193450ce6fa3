#!/usr/bin/env bash
# The pictures of docs/input-files.md "OME-Zarr levels": a VDB cloud (fractal noise inside a
# sphere, written with python3-openvdb, background 0, inactive where the noise is 0), ch2's
# levels 0, 1 and 2 as an OME-Zarr pyramid (python3-zarr; each level the 2x2x2 mean of the
# one before) rendered side by side, and a time series (a 4D NIfTI of a blob that moves and
# pulses, written with nibabel) as a GIF by `splat rotate --time-steps`.
# Usage: bash tools/gallery/sparse_gallery.sh   (after tools/build.sh)
set -euo pipefail
cd "$(dirname "$0")/../.."
S=build/bin/splat
G=splat/docs/images
mkdir -p $G
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

/usr/bin/python3 - "$tmp" <<'PY'
import os
import sys

import nibabel as nib
import numcodecs
import numpy as np
import pyopenvdb as vdb
import zarr

out = sys.argv[1]
rng = np.random.default_rng(7)

# A cloud: fractal noise (octaves of random-phase plane waves) inside a sphere of radius 44.
n = 112
x, y, z = np.meshgrid(*[np.arange(n, dtype=np.float32)] * 3, indexing="ij")
noise = np.zeros((n, n, n), np.float32)
for octave in range(5):
    f = 0.06 * 2 ** octave
    for _ in range(6):
        k = rng.normal(size=3)
        k *= f / np.linalg.norm(k)
        noise += 0.55 ** octave * np.sin(k[0] * x + k[1] * y + k[2] * z + rng.uniform(0, 6.3))
c = (n - 1) / 2.0
r = np.sqrt((x - c) ** 2 + (y - c) ** 2 + ((z - c) * 1.4) ** 2) / 44.0
density = np.clip(noise / 2.5 + 1.0 - 1.3 * r ** 2, 0.0, None).astype(np.float32)
g = vdb.FloatGrid(background=0.0)
g.copyFromArray(density, ijk=(0, 0, 0), tolerance=0.0)
g.name = "density"
vdb.write(os.path.join(out, "cloud.vdb"), grids=[g])
print(f"cloud.vdb: {g.activeVoxelCount()} active voxels of {n ** 3}")

# ch2 as a 3-level OME-Zarr pyramid (RAS already; cropped to even sizes).
img = nib.load("/usr/share/mricron/templates/ch2.nii.gz")
a = np.asarray(img.dataobj, dtype=np.float32)[:180, :216, :180]
s0, o0 = np.array(img.header.get_zooms()[:3], float), img.affine[:3, 3]
root = zarr.open_group(os.path.join(out, "ch2.zarr"), mode="w")
datasets = []
for L in range(3):
    root.create_dataset(str(L), data=np.ascontiguousarray(a.transpose(2, 1, 0)),
                        chunks=(32, 32, 32), compressor=numcodecs.Zlib(level=6))
    s, o = s0 * 2 ** L, o0 + (2 ** L - 1) / 2.0 * s0
    datasets.append({"path": str(L), "coordinateTransformations": [
        {"type": "scale", "scale": list(s[::-1])},
        {"type": "translation", "translation": list(o[::-1])}]})
    if L == 2:
        break
    m = [d // 2 for d in a.shape]
    a = a.astype(np.float64).reshape(m[0], 2, m[1], 2, m[2], 2).mean(axis=(1, 3, 5)).astype(
        np.float32)
root.attrs["multiscales"] = [{"version": "0.4", "name": "ch2", "datasets": datasets,
                              "axes": [{"name": c, "type": "space", "unit": "millimeter"}
                                       for c in "zyx"]}]

# A time series: a blob circling the centre and pulsing, 12 steps of 48^3.
n, steps = 48, 12
x, y, z = np.meshgrid(*[np.arange(n, dtype=np.float32)] * 3, indexing="ij")
series = np.zeros((n, n, n, steps), np.float32)
for t in range(steps):
    a = 2 * np.pi * t / steps
    cx, cy, cz = 23.5 + 10 * np.cos(a), 23.5 + 10 * np.sin(a), 23.5 + 4 * np.sin(2 * a)
    radius = 6.0 + 2.5 * np.sin(2 * a)
    r2 = (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2
    series[..., t] = np.exp(-r2 / (2 * radius ** 2)) + 0.5 * np.exp(
        -((x - 23.5) ** 2 + (y - 23.5) ** 2) / 8.0 - (z - 23.5) ** 2 / 200.0)
nib.save(nib.Nifti1Image(series, np.eye(4)), os.path.join(out, "blob4d.nii.gz"))
PY

# The cloud: pre-classified dvr, a white ramp on a dark sky.
cat > $tmp/cloud.json <<'JSON'
{"domain": "normalized", "unit_distance": 1.0,
 "points": [[0, 0, 0, 0, 0], [0.08, 0.75, 0.8, 0.9, 0.0], [0.35, 0.95, 0.95, 1.0, 0.25],
            [1, 1, 1, 1, 0.6]]}
JSON
$S render $tmp/cloud.vdb --tf $tmp/cloud.json --shade --azimuth 30 --elevation 15 \
    --background 0.05,0.08,0.2 --pixel-size 0.42 --size 320x320 -o $G/vdb_cloud.png
# ch2's levels: the same view of each level, side by side.
for L in 0 1 2; do
    $S render $tmp/ch2.zarr --zarr-level $L --tf mri-head --shade --azimuth 150 --elevation 10 \
        --size 220x220 -o $tmp/ch2_level$L.png
done
oiiotool $tmp/ch2_level0.png $tmp/ch2_level1.png $tmp/ch2_level2.png --mosaic 3x1 \
    -o $G/zarr_levels.png
# The time series: one frame per step, the camera fixed.
cat > $tmp/blob.json <<'JSON'
{"domain": "normalized", "unit_distance": 1.0,
 "points": [[0, 0, 0, 0, 0], [0.2, 0.9, 0.4, 0.1, 0.0], [0.45, 1.0, 0.7, 0.2, 0.15],
            [1, 1, 1, 0.8, 0.9]]}
JSON
$S rotate $tmp/blob4d.nii.gz --time-steps 0:11 --tf $tmp/blob.json --shade --azimuth 20 \
    --elevation 25 --background 0.05,0.05,0.1 --pixel-size 0.3 --size 160x160 \
    -o $tmp/series --gif $G/time_series.gif
ls -l $G/vdb_cloud.png $G/zarr_levels.png $G/time_series.gif
