#!/usr/bin/python3
"""Writes the test data of splat's OpenVDB and OME-Zarr readers with the formats' own
libraries (python3-openvdb, python3-zarr with numcodecs, nibabel), so that the readers are
checked against code splat did not write.

    make_sparse_data.py OUTDIR [--shell N]

OUTDIR/same.nii.gz, same.vdb, same.zarr: one volume (an off-centre blob and two corner
markers on a background of 3, spacing 0.75, 1.125, 1.25, origin 2, -3, 5) in the three formats
with the same geometry; the VDB's voxels equal to the background are inactive and the
Zarr's chunks that hold only the background are not stored (fill_value 3). same.zarr has a
second level (every other sample, scale doubled).
OUTDIR/pyramid.zarr: a 3-level pyramid of a 32^3 blob (spacing 0.5, origin 1, 2, 3), each
level the exact 2x2x2 mean of the one before on coarserGrid's grid (twice the spacing, origin
moved by half a finer voxel), as splat's level of detail merges voxels; pyramid_1.nii.gz and
pyramid_2.nii.gz: levels 1 and 2 as NIfTI with the same geometry.
OUTDIR/dtypes/*.zarr: the integer ramp (i + 2 j + 3 k) % 97 as bare Zarr arrays in every
dtype, byte order and compressor splat reads, chunks (3, 4, 5) so that edge chunks are
partial; also Fortran order and '/' as the dimension separator.
OUTDIR/tczyx.zarr: a 5D image (2 time points, 3 channels): value 1000 t + 100 c + ramp.
OUTDIR/grids.vdb: a vec3s grid 'velocity', a float grid 'temperature' (background -1, voxel 0.25)
and a float grid 'smoke' with an active tile; OUTDIR/rotated.vdb: a grid whose transform
turns about z (refused).
OUTDIR/blobs.nii.gz, blobs.vdb: four separated blobs (one below b) and two corner markers on a
background of 3 in a 64x48x40 box, spacing 1, 0.75, 1.25: the VDB's bricks mostly hold only b.
With --shell N: OUTDIR/shell_N.vdb only, a thin spherical shell of radius 0.45 N (one
voxel thick) in an N^3 box, for tools/bench/sparse_bench.py.
Exit status 77 when a library is missing (the tests are then skipped).
"""
import os
import sys

try:
    import numpy as np
    import pyopenvdb as vdb
    import zarr
    import numcodecs
    import nibabel as nib
except ImportError as e:
    print(f"make_sparse_data: {e} (tools/setup.sh installs python3-openvdb, python3-zarr, "
          "python3-nibabel)", file=sys.stderr)
    sys.exit(77)

BACKGROUND = 3.0
SPACING = (0.75, 1.125, 1.25)  # exact in float32, as NIfTI stores them
ORIGIN = (2.0, -3.0, 5.0)
DIMS = (20, 17, 14)  # x, y, z


def same_volume():
    """float32 samples indexed [x, y, z]."""
    x, y, z = np.meshgrid(*[np.arange(n, dtype=np.float64) for n in DIMS], indexing="ij")
    c = (8.0, 7.5, 6.0)
    r2 = ((x - c[0]) * SPACING[0]) ** 2 + ((y - c[1]) * SPACING[1]) ** 2 + \
         ((z - c[2]) * SPACING[2]) ** 2
    blob = 10.0 * np.exp(-r2 / (2 * 3.0 ** 2))
    blob[blob < 0.05] = 0.0  # sparse: the blob ends
    d = (BACKGROUND + blob).astype(np.float32)
    d[0, 0, 0] = BACKGROUND + 4.0  # markers at two corners: the active box is the volume's
    d[-1, -1, -1] = BACKGROUND + 6.0
    return d


BLOBS_DIMS = (64, 48, 40)
BLOBS_SPACING = (1.0, 0.75, 1.25)


def blobs_volume():
    """Four separated Gaussian blobs (one of them below b) and two corner markers (so that
    the VDB's active box is the volume's) on a background of 3, float32 indexed [x, y, z]:
    most of the box holds only b."""
    x, y, z = np.meshgrid(*[np.arange(n, dtype=np.float64) for n in BLOBS_DIMS], indexing="ij")
    d = np.zeros(BLOBS_DIMS)
    for (cx, cy, cz, h) in [(10, 10, 9, 10.0), (52, 36, 10, 6.0), (14, 37, 30, -2.0),
                            (50, 12, 29, 8.0)]:
        r2 = (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2
        d += h * np.exp(-r2 / (2 * 1.3 ** 2))
    d[np.abs(d) < 0.02] = 0.0  # each blob ends
    d[0, 0, 0] = 4.0
    d[-1, -1, -1] = 6.0
    return (BACKGROUND + d).astype(np.float32)


def write_vdb(path, grids):
    vdb.write(path, grids=grids)


def float_grid(d, name, background, spacing, origin):
    g = vdb.FloatGrid(background=background)
    g.copyFromArray(d, ijk=(0, 0, 0), tolerance=0.0)
    g.name = name
    m = [[spacing[0], 0, 0, 0], [0, spacing[1], 0, 0], [0, 0, spacing[2], 0],
         [origin[0], origin[1], origin[2], 1]]
    g.transform = vdb.createLinearTransform(m)
    return g


def write_ome(path, levels, scales, translation, axes, compressors, fill):
    """levels: arrays in axis order; scales: one list per level."""
    root = zarr.open_group(path, mode="w")
    datasets = []
    for n, (a, s, comp) in enumerate(zip(levels, scales, compressors)):
        root.create_dataset(str(n), data=a, chunks=(5,) * a.ndim if a.ndim == 3 else
                            (1,) * (a.ndim - 3) + (5, 5, 5), compressor=comp,
                            fill_value=fill, write_empty_chunks=False)
        datasets.append({"path": str(n), "coordinateTransformations": [
            {"type": "scale", "scale": list(s)},
            {"type": "translation", "translation": list(translation)}]})
    kinds = {"t": "time", "c": "channel"}
    root.attrs["multiscales"] = [{
        "version": "0.4", "name": "test",
        "axes": [{"name": a, "type": kinds.get(a, "space")} for a in axes],
        "datasets": datasets}]


def write_pyramid(out):
    n, s, origin = 32, 0.5, np.array([1.0, 2.0, 3.0])
    x, y, z = np.meshgrid(*[np.arange(n, dtype=np.float64)] * 3, indexing="ij")
    r2 = (x - 13.0) ** 2 + (y - 17.5) ** 2 + (z - 15.0) ** 2
    levels = [(8.0 * np.exp(-r2 / (2 * 6.0 ** 2)) * (1 + 0.5 * np.sin(x / 2.0))).astype(np.float32)]
    levels[0][levels[0] < 0.02] = 0.0
    for _ in range(2):
        a = levels[-1].astype(np.float64)
        m = a.shape[0] // 2
        levels.append(a.reshape(m, 2, m, 2, m, 2).mean(axis=(1, 3, 5)).astype(np.float32))
    spacings = [s * 2 ** L for L in range(3)]
    origins = [origin + (2 ** L - 1) / 2.0 * s for L in range(3)]
    for L in (1, 2):
        affine = np.diag([spacings[L]] * 3 + [1.0])
        affine[:3, 3] = origins[L]
        nib.save(nib.Nifti1Image(levels[L], affine), os.path.join(out, f"pyramid_{L}.nii.gz"))
    root = zarr.open_group(os.path.join(out, "pyramid.zarr"), mode="w")
    datasets = []
    for L, a in enumerate(levels):
        root.create_dataset(str(L), data=np.ascontiguousarray(a.transpose(2, 1, 0)),
                            chunks=(8, 8, 8), compressor=numcodecs.Zlib(level=1),
                            fill_value=0.0, write_empty_chunks=False)
        datasets.append({"path": str(L), "coordinateTransformations": [
            {"type": "scale", "scale": [spacings[L]] * 3},
            {"type": "translation", "translation": list(origins[L][::-1])}]})
    root.attrs["multiscales"] = [{
        "version": "0.4", "name": "pyramid",
        "axes": [{"name": a, "type": "space", "unit": "millimeter"} for a in "zyx"],
        "datasets": datasets}]


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    if len(sys.argv) > 3 and sys.argv[2] == "--shell":
        n = int(sys.argv[3])
        g = vdb.FloatGrid(background=0.0)
        g.name = "density"
        acc = g.getAccessor()
        r0 = 0.45 * n
        c = (n - 1) / 2.0
        # One voxel thick: the voxels whose distance to the centre rounds to r0, one
        # z-slab at a time (numpy) to keep memory small.
        y, x = np.mgrid[0:n, 0:n].astype(np.float64)
        for k in range(n):
            r = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (k - c) ** 2)
            jj, ii = np.nonzero(np.abs(r - r0) < 0.5)
            for i, j in zip(ii.tolist(), jj.tolist()):
                acc.setValueOn((i, j, k), 1.0)
        write_vdb(os.path.join(out, f"shell_{n}.vdb"), [g])
        print(g.activeVoxelCount())
        return

    d = same_volume()
    nib.save(nib.Nifti1Image(d, np.array([[SPACING[0], 0, 0, ORIGIN[0]],
                                          [0, SPACING[1], 0, ORIGIN[1]],
                                          [0, 0, SPACING[2], ORIGIN[2]],
                                          [0, 0, 0, 1]])), os.path.join(out, "same.nii.gz"))
    write_vdb(os.path.join(out, "same.vdb"),
              [float_grid(d, "density", BACKGROUND, SPACING, ORIGIN)])
    zyx = np.ascontiguousarray(d.transpose(2, 1, 0))
    write_ome(os.path.join(out, "same.zarr"), [zyx, zyx[::2, ::2, ::2]],
              [SPACING[::-1], [2 * s for s in SPACING[::-1]]], ORIGIN[::-1], "zyx",
              [numcodecs.Blosc(cname="lz4", clevel=5, shuffle=numcodecs.Blosc.SHUFFLE),
               numcodecs.Zlib(level=6)], BACKGROUND)

    write_pyramid(out)

    # Every dtype, byte order and compressor.
    k, j, i = np.meshgrid(np.arange(9), np.arange(11), np.arange(13), indexing="ij")
    ramp = (i + 2 * j + 3 * k) % 97
    os.makedirs(os.path.join(out, "dtypes"), exist_ok=True)
    compressors = {"none": None, "blosc": numcodecs.Blosc(cname="zstd", clevel=3,
                                                          shuffle=numcodecs.Blosc.BITSHUFFLE),
                   "zlib": numcodecs.Zlib(level=1), "gzip": numcodecs.GZip(level=1)}
    for dt in ["|i1", "|u1", "<i2", ">i2", "<u2", ">u2", "<i4", ">u4", "<i8", ">u8", "<f4",
               ">f4", "<f8", ">f8"]:
        for cname, comp in compressors.items():
            name = f"{dt[1:]}_{'be' if dt[0] == '>' else 'le'}_{cname}.zarr"
            z = zarr.open_array(os.path.join(out, "dtypes", name), mode="w", shape=ramp.shape,
                                chunks=(3, 4, 5), dtype=dt, compressor=comp, fill_value=0)
            z[...] = ramp.astype(dt)
    z = zarr.open_array(os.path.join(out, "dtypes", "fortran.zarr"), mode="w", shape=ramp.shape,
                        chunks=(3, 4, 5), dtype="<u2", order="F", compressor=None)
    z[...] = ramp
    store = zarr.DirectoryStore(os.path.join(out, "dtypes", "nested.zarr"),
                                dimension_separator="/")
    z = zarr.open_array(store, mode="w", shape=ramp.shape, chunks=(3, 4, 5), dtype="<i2")
    z[...] = ramp

    t, c = 2, 3
    five = np.zeros((t, c) + ramp.shape, dtype="<u2")
    for a in range(t):
        for b in range(c):
            five[a, b] = 1000 * a + 100 * b + ramp
    write_ome(os.path.join(out, "tczyx.zarr"), [five], [[1, 1, 2.0, 1.5, 0.5]],
              [0, 0, 10.0, 20.0, 30.0], "tczyx", [numcodecs.Zlib(level=1)], 0)

    small = (np.arange(4 * 5 * 6, dtype=np.float32).reshape(4, 5, 6) % 7) + 1
    grids = [float_grid(small, "smoke", 0.0, (1, 1, 1), (0, 0, 0))]
    tile = grids[0]
    tile.fill((16, 0, 0), (23, 7, 7), 2.5)  # an 8^3 active tile
    temp = vdb.FloatGrid(background=-1.0)
    temp.name = "temperature"
    temp.copyFromArray(small * 2, ijk=(10, 20, 30), tolerance=0.0)
    temp.transform = vdb.createLinearTransform(voxelSize=0.25)
    vel = vdb.Vec3SGrid()
    vel.name = "velocity"
    vel.getAccessor().setValueOn((1, 2, 3), (1.0, 0.0, 0.0))
    write_vdb(os.path.join(out, "grids.vdb"), [vel, temp] + grids)
    turned = float_grid(small, "density", 0.0, (1, 1, 1), (0, 0, 0))
    turned.transform = vdb.createLinearTransform(
        [[0.6, 0.8, 0, 0], [-0.8, 0.6, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    write_vdb(os.path.join(out, "rotated.vdb"), [turned])

    b = blobs_volume()
    affine = np.diag([1.0, 1.0, 1.0, 1.0])
    affine[:3, :3] = np.diag(BLOBS_SPACING)
    affine[:3, 3] = ORIGIN
    nib.save(nib.Nifti1Image(b, affine), os.path.join(out, "blobs.nii.gz"))
    write_vdb(os.path.join(out, "blobs.vdb"),
              [float_grid(b, "density", BACKGROUND, BLOBS_SPACING, ORIGIN)])


main()
