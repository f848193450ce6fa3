#!/usr/bin/python3
"""OME-Zarr levels at scale: an N^3 pyramid (default 512^3 float32, 512 MiB at level 0)
rendered at level 0 within a memory budget (`--zarr-level 0 --rank-memory MIB`: bricks one
after another, each reading only its chunks), and at its default level (the level the
`--lod` rule picks for the view) against the NIfTI of that level. A benchmark, not a test.

    tools/bench/zarr_levels_bench.py SPLAT_EXE [--n 512] [--budget 256] [--lod 1]
                                     [--repeats 5] [--dir DIR] [-- FLAGS]

The pyramid is written once into DIR (default /tmp/splat_zarr_bench) with python3-zarr:
pyramid_N.zarr, levels 0..3 of a modulated sphere (radius 0.45 N, about 38% of the box
non-zero), each level the exact 2x2x2 mean of the one before on coarserGrid's grid, chunks
64^3, zlib; and pyramid_N_L.nii.gz, level L as NIfTI (nibabel). Every render is
`splat render VOLUME --mode mip --size 256x256` (FLAGS after `--` are added) under nice with
/usr/bin/time -v; it prints wall seconds and peak RSS in MiB: level 0 whole (what it takes
without a budget), level 0 within the budget, and the default level against the NIfTI of
that level, interleaved (Zarr, NIfTI, Zarr, NIfTI, ...), with the median ratio.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys

import numpy as np

argv = sys.argv[1:]
flags = argv[argv.index("--") + 1:] if "--" in argv else []
argv = argv[:argv.index("--")] if "--" in argv else argv
ap = argparse.ArgumentParser()
ap.add_argument("splat")
ap.add_argument("--n", type=int, default=512)
ap.add_argument("--budget", type=float, default=256, help="--rank-memory, MiB")
ap.add_argument("--lod", default="1", help="--lod of the default-level renders")
ap.add_argument("--repeats", type=int, default=5)
ap.add_argument("--dir", default="/tmp/splat_zarr_bench")
a = ap.parse_args(argv)
os.makedirs(a.dir, exist_ok=True)
LEVELS, CHUNK = 4, 64


def slab(n, z0, z1):
    """Level-0 samples of z in [z0, z1), indexed [z, y, x], float32."""
    c, r0 = (n - 1) / 2.0, 0.45 * n
    z, y, x = np.meshgrid(np.arange(z0, z1, dtype=np.float32),
                          np.arange(n, dtype=np.float32), np.arange(n, dtype=np.float32),
                          indexing="ij")
    r = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)
    f = 100.0 * np.maximum(0.0, 1.0 - r / r0) * \
        (1.0 + 0.3 * np.sin(x / 7.0) * np.sin(y / 11.0) * np.sin(z / 5.0))
    return f.astype(np.float32)


def mean2(a):
    """The 2x2x2 mean (float64 sums, as coarserSplats averages), float32."""
    z, y, x = (s // 2 for s in a.shape)
    return a.astype(np.float64).reshape(z, 2, y, 2, x, 2).mean(axis=(1, 3, 5)).astype(np.float32)


def write_pyramid(path, n):
    import zarr
    import numcodecs
    root = zarr.open_group(path, mode="w")
    arrays, datasets = [], []
    for L in range(LEVELS):
        m = n >> L
        arrays.append(root.create_dataset(str(L), shape=(m, m, m), dtype="<f4",
                                          chunks=(min(CHUNK, m),) * 3, fill_value=0.0,
                                          compressor=numcodecs.Zlib(level=1),
                                          write_empty_chunks=False))
        s, t = 2.0 ** L, (2.0 ** L - 1) / 2.0
        datasets.append({"path": str(L), "coordinateTransformations": [
            {"type": "scale", "scale": [s] * 3}, {"type": "translation", "translation": [t] * 3}]})
    step = CHUNK  # level-0 slabs of one chunk (64 MiB at 512^2), even at every level
    for z0 in range(0, n, step):
        a0 = slab(n, z0, min(n, z0 + step))
        for L in range(LEVELS):
            arrays[L][z0 >> L:(z0 >> L) + a0.shape[0]] = a0
            if L + 1 < LEVELS:
                a0 = mean2(a0)
    root.attrs["multiscales"] = [{
        "version": "0.4", "name": f"pyramid_{n}",
        "axes": [{"name": c, "type": "space"} for c in "zyx"], "datasets": datasets}]


def write_nifti(zarr_path, level, path):
    import zarr
    import nibabel as nib
    a = zarr.open_group(zarr_path, mode="r")[str(level)][...]
    s, t = 2.0 ** level, (2.0 ** level - 1) / 2.0
    affine = np.diag([s, s, s, 1.0])
    affine[:3, 3] = t
    nib.save(nib.Nifti1Image(np.ascontiguousarray(a.transpose(2, 1, 0)), affine), path)


def run(volume, extra):
    r = subprocess.run(["nice", "-n", "10", "/usr/bin/time", "-v", a.splat, "render", volume,
                        "--mode", "mip", "--size", "256x256",
                        "-o", os.path.join(a.dir, "out.png")] + extra + flags,
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {volume} {extra}: {r.stderr.strip().splitlines()[-1:]}")
    wall = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", r.stderr)
    secs = int(wall.group(1) or 0) * 3600 + int(wall.group(2)) * 60 + float(wall.group(3))
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr).group(1))
    return secs, rss / 1024.0, r.stdout


zarr_path = os.path.join(a.dir, f"pyramid_{a.n}.zarr")
if not os.path.exists(os.path.join(zarr_path, ".zattrs")):
    write_pyramid(zarr_path, a.n)
# The level the rule picks for the view (render prints it).
_, _, out = run(zarr_path, ["--lod", a.lod])
m = re.search(r"reading OME-Zarr level (\d+) of", out)
level = int(m.group(1)) if m else 0
nifti = os.path.join(a.dir, f"pyramid_{a.n}_{level}.nii.gz")
if not os.path.exists(nifti):
    write_nifti(zarr_path, level, nifti)
print(f"pyramid {a.n}^3 float32 ({a.n ** 3 * 4 / 2 ** 20:.0f} MiB at level 0), --mode mip "
      f"--size 256x256 {' '.join(flags)}")
print(f"{'render':<48} {'seconds':>8} {'peak MiB':>9}")
secs, rss, _ = run(zarr_path, ["--zarr-level", "0"])
print(f"{'level 0, whole (no budget)':<48} {secs:>8.2f} {rss:>9.0f}")
secs, rss, _ = run(zarr_path, ["--zarr-level", "0", "--rank-memory", f"{a.budget:g}"])
print(f"{'level 0, --rank-memory ' + f'{a.budget:g}':<48} {secs:>8.2f} {rss:>9.0f}")
sys.stdout.flush()
times = {"zarr": [], "nifti": []}
for _ in range(a.repeats):
    for name, volume in (("zarr", zarr_path), ("nifti", nifti)):
        secs, rss, _ = run(volume, ["--lod", a.lod])
        times[name].append(secs)
        times[name + " rss"] = rss
for name, label in (("zarr", f"default level {level} (--lod {a.lod}), Zarr"),
                    ("nifti", f"level {level} as NIfTI (--lod {a.lod})")):
    print(f"{label:<48} {statistics.median(times[name]):>8.2f} {times[name + ' rss']:>9.0f}")
ratios = [z / n for z, n in zip(times["zarr"], times["nifti"])]
print(f"Zarr / NIfTI wall time, median of {a.repeats} interleaved pairs: "
      f"{statistics.median(ratios):.2f} (range {min(ratios):.2f}-{max(ratios):.2f})")
