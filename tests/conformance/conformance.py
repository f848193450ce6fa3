#!/usr/bin/python3
"""Conformance of splat's loaders against nibabel and pydicom.

Runs `splat info` over every NIfTI / ANALYZE / DICOM file of the two third-party corpora
Debian ships (python3-nibabel's nibabel/tests/data and nibabel/nicom/tests/data,
python3-pydicom's pydicom/data/test_files) and compares what splat reads with what the
oracle reads, in quantities that do not depend on splat's reorientation (splat reorders
every volume's axes by flips/permutations and keeps the rest of the rotation as its
direction):

  * dimensions (as a sorted triple),
  * the world (RAS millimetres) positions of the eight corner voxel centres, from the origin
    and axes `splat info` prints (a left-right mirror or a dropped rotation moves them; the
    grid is affine, so every voxel is then within the same distance),
  * the scaled values: minimum, maximum and mean.

Each file is one of
  same      read identically (within 1e-3 mm and 1e-4 relative in the mean),
  refused   splat refuses it with one line (the reason is printed in the table),
  warned    splat reads it differently and says so on stderr,
  WRONG     splat reads it differently and says nothing: a failure of this test,
  n/a       the oracle cannot read it either (not an image, a codec pydicom lacks, ...).

Files with a known answer are held to it (EXPECTED below: a result and a phrase of its
detail), so that a file splat once refused and now reads, or refuses for a stated reason,
stays that way.

Usage: conformance.py SPLAT [--table FILE]   exit 1 when any file is WRONG, splat crashed, or
a file of EXPECTED gave another answer.
"""
import glob
import gzip
import os
import shutil
import subprocess
import sys
import tempfile
import warnings

import numpy as np

warnings.filterwarnings("ignore")

NIB = "/usr/lib/python3/dist-packages/nibabel"
PYD = "/usr/lib/python3/dist-packages/pydicom/data/test_files"

# label -> (result, a phrase its detail must hold)
EXPECTED = {
    # RLE Lossless is decoded by splat (DICOM PS3.5 Annex G), 16- and 32-bit samples alike;
    # GDCM's decoder asserts on the 32-bit dose.
    "pydicom/MR_small_RLE.dcm": ("same", ""),
    "pydicom/rtdose_rle_1frame.dcm": ("same", ""),
    "pydicom/JPEG2000.dcm": ("same", ""),
    # The same file with four bytes of its codestream's SIZ marker overwritten by a sequence
    # delimiter: pydicom parses the fragment (its own test) but no decoder reads the image
    # (Pillow: a 3722445056 x 1024 "decompression bomb"); splat names the bad SIZ.
    "pydicom/JPEG2000-embedded-sequence-delimiter.dcm": ("n/a", "corrupt JPEG 2000 codestream"),
    # A well-formed file without Pixel Data.
    "nibabel/nicom/csa_slice_norm.dcm": ("n/a", "without pixel data"),
    # A CIFTI-2 connectivity matrix (NIfTI-2, intent code 3001): not a volume.
    "nibabel/row_major.dconn.nii": ("n/a", "not a volume: a CIFTI-2 matrix"),
}


def corpus(tmp):
    """(label, path, kind) of every NIfTI/ANALYZE/DICOM file of both corpora."""
    files = []
    for p in sorted(glob.glob(NIB + "/tests/data/*")):
        b = os.path.basename(p)
        if b.endswith((".nii", ".nii.gz", ".hdr")):
            files.append(("nibabel/" + b, p, "nifti"))
        elif b.endswith(".dcm"):
            files.append(("nibabel/" + b, p, "dicom"))
    for p in sorted(glob.glob(NIB + "/nicom/tests/data/*")):
        b = os.path.basename(p)
        if b.endswith(".dcm"):
            files.append(("nibabel/nicom/" + b, p, "dicom"))
        elif b.endswith(".dcm.gz"):
            out = os.path.join(tmp, b[:-3])
            with gzip.open(p) as src, open(out, "wb") as dst:
                shutil.copyfileobj(src, dst)
            files.append(("nibabel/nicom/" + b, out, "dicom"))
    for p in sorted(glob.glob(PYD + "/*.dcm")):
        files.append(("pydicom/" + os.path.basename(p), p, "dicom"))
    return files


def splat_read(splat, path):
    r = subprocess.run([splat, "info", path], capture_output=True, text=True, timeout=60)
    out = {"rc": r.returncode, "stderr": r.stderr.strip()}
    for line in r.stdout.splitlines():
        key, _, value = line.partition(":")
        value = value.strip()
        if key == "dimensions":
            out["dims"] = tuple(int(x) for x in value.split("(")[0].split(" x "))
        elif key == "origin":
            a = value.partition(", last sample at ")[0]
            out["first"] = np.array([float(x) for x in a.strip("()").split(",")])
        elif key == "axes":
            parts = value.replace("(oblique)", "").split("(")[1:]
            out["axes"] = [np.array([float(x) for x in p.split(")")[0].split(",")])
                           for p in parts]
        elif key == "values":
            rng, _, mean = value.partition(", mean ")
            lo, _, hi = rng.partition(" .. ")
            out["values"] = (float(lo), float(hi), float(mean))
    return out


def corners(affine, dims):
    """World positions (8 x 3) of the corner voxel centres of a 3D grid."""
    c = np.array([[i, j, k, 1] for i in (0, dims[0] - 1) for j in (0, dims[1] - 1)
                  for k in (0, dims[2] - 1)], float)
    return (affine @ c.T)[:3].T


def splat_affine(s):
    a = np.eye(4)
    for n in range(3):
        a[:3, n] = s["axes"][n]
    a[:3, 3] = s["first"]
    return a


def nibabel_read(path):
    import nibabel as nib
    img = nib.load(path)
    data = np.asarray(img.dataobj, dtype=np.float64)
    while data.ndim > 3:  # splat loads the first volume of a 4D file
        data = data[..., 0]
    while data.ndim < 3:
        data = data[..., None]
    return data.shape, img.affine, data


def mosaic_read(path):
    """nibabel's reading of a Siemens mosaic (None for any other DICOM file)."""
    from nibabel.nicom import dicomwrappers
    try:
        w = dicomwrappers.wrapper_from_file(path)
    except Exception:
        return None
    if not w.is_mosaic:
        return None
    data = np.asarray(w.get_data(), dtype=np.float64)
    affine = np.diag([-1.0, -1.0, 1.0, 1.0]) @ w.affine  # LPS -> RAS
    return data.shape, affine, data, True


def pydicom_read(path):
    import pydicom
    mosaic = mosaic_read(path)
    if mosaic is not None:
        return mosaic
    ds = pydicom.dcmread(path)
    a = ds.pixel_array.astype(np.float64)
    if a.ndim != 2:
        raise ValueError("not one scalar frame: pixel array shape %s" % (a.shape,))
    if int(getattr(ds, "NumberOfFrames", 1) or 1) != 1:
        raise ValueError("not one scalar frame: %s frames" % ds.NumberOfFrames)
    a = a * float(getattr(ds, "RescaleSlope", 1) or 1) + float(getattr(ds, "RescaleIntercept", 0) or 0)
    rows, cols = a.shape
    affine = np.eye(4)
    if "ImagePositionPatient" in ds and "ImageOrientationPatient" in ds:
        o = [float(x) for x in ds.ImageOrientationPatient]
        dy, dx = ([float(x) for x in ds.PixelSpacing] if "PixelSpacing" in ds else (1.0, 1.0))
        r, c = np.array(o[:3]), np.array(o[3:])
        lps = np.eye(4)
        lps[:3, 0] = r * dx
        lps[:3, 1] = c * dy
        lps[:3, 2] = np.cross(r, c)
        lps[:3, 3] = [float(x) for x in ds.ImagePositionPatient]
        affine = np.diag([-1.0, -1.0, 1.0, 1.0]) @ lps  # LPS -> RAS
        geometry = True
    else:
        geometry = False
    return (cols, rows, 1), affine, a, geometry


def classify(label, path, kind, splat):
    s = splat_read(splat, path)
    try:
        if kind == "nifti":
            shape, affine, data = nibabel_read(path)
            geometry = True
        else:
            shape, affine, data, geometry = pydicom_read(path)
    except ValueError as e:  # the oracle reads it, but not as one scalar 3D image
        if s["rc"] > 0 and str(e).startswith("not one scalar frame"):
            return "refused", reason(s, path)
        return classify_oracle_failure(s, path, e)
    except Exception as e:  # the oracle cannot read it either
        return classify_oracle_failure(s, path, e)

    if s["rc"] < 0:
        return "WRONG", "splat died with signal %d" % -s["rc"]
    if s["rc"] != 0:
        return "refused", reason(s, path)
    problems = []
    if tuple(sorted(s["dims"])) != tuple(sorted(int(x) for x in shape)):
        problems.append("dims %s, oracle %s" % (s["dims"], tuple(shape)))
    lo, hi, mean = s["values"]
    if not (np.isclose(lo, data.min(), rtol=1e-5, atol=1e-3) and
            np.isclose(hi, data.max(), rtol=1e-5, atol=1e-3) and
            np.isclose(mean, data.mean(), rtol=2e-5, atol=1e-3)):
        problems.append("values %g..%g mean %g, oracle %g..%g mean %g" %
                        (lo, hi, mean, data.min(), data.max(), data.mean()))
    if geometry and not problems:
        oracle = corners(affine, shape)
        mine = corners(splat_affine(s), s["dims"])
        # Each oracle corner's distance to the nearest of splat's corners.
        err = max(np.linalg.norm(mine - c, axis=1).min() for c in oracle)
        if err > 1e-3:
            problems.append("corner voxels off by %.3g mm" % err)
    if not problems:
        return "same", ""
    if "warning" in s["stderr"]:
        first = [l for l in s["stderr"].splitlines() if "warning" in l][0]
        return "warned", "; ".join(problems) + " — " + first.split(": ", 3)[-1][:90]
    return "WRONG", "; ".join(problems)


def classify_oracle_failure(s, path, e):
    oracle = "%s: %s" % (type(e).__name__, str(e).splitlines()[0][:70] if str(e) else "")
    if s["rc"] < 0:
        return "WRONG", "splat died with signal %d" % -s["rc"]
    if s["rc"] == 0:
        return "n/a", "splat reads it; the oracle cannot (%s)" % oracle
    return "n/a", "the oracle refuses too; splat: " + reason(s, path)


def reason(s, path):
    err = s["stderr"].splitlines()[-1] if s["stderr"] else "(no message)"
    err = err.replace("splat: error: ", "").replace(path + ": ", "")
    return err.replace("|", "/")[:150]


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    splat = sys.argv[1]
    table = sys.argv[sys.argv.index("--table") + 1] if "--table" in sys.argv else None
    if not os.path.isdir(NIB) or not os.path.isdir(PYD):
        print("conformance: python3-nibabel / python3-pydicom are not installed (tools/setup.sh)")
        return 1
    tmp = tempfile.mkdtemp(prefix="splat_conformance_")
    try:
        rows = [(label,) + classify(label, path, kind, splat)
                for label, path, kind in corpus(tmp)]
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    counts = {}
    for _, result, _ in rows:
        counts[result] = counts.get(result, 0) + 1
    lines = ["| file | result | detail |", "|---|---|---|"]
    lines += ["| %s | %s | %s |" % r for r in rows]
    summary = ", ".join("%s %d" % (k, counts[k]) for k in sorted(counts))
    text = "\n".join(lines) + "\n\n%d files: %s\n" % (len(rows), summary)
    if table:
        with open(table, "w") as f:
            f.write(text)
    for r in rows:
        if r[1] == "WRONG":
            print("WRONG: %s: %s" % (r[0], r[2]))
    unexpected = 0
    seen = {r[0]: r for r in rows}
    for label, (result, phrase) in EXPECTED.items():
        r = seen.get(label)
        if r is None or r[1] != result or phrase not in r[2]:
            unexpected += 1
            print("UNEXPECTED: %s: %s, expected %s%s" % (
                label, "missing" if r is None else "%s (%s)" % (r[1], r[2]), result,
                " with '%s'" % phrase if phrase else ""))
    print("conformance: %d files: %s" % (len(rows), summary))
    return 1 if counts.get("WRONG", 0) or unexpected else 0


if __name__ == "__main__":
    sys.exit(main())
