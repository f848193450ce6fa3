#!/usr/bin/python3
"""One world frame for every format: no left-right mirror between them.

One asymmetric volume (an L-shaped bar, a ramp and one brightest marker voxel) with a known
RAS geometry is written

  * as NIfTI by nibabel, in RAS index order and again stored radiologically (x flipped, a
    negative x axis in the affine),
  * as a DICOM series by pydicom (LPS: columns to patient left, rows to posterior, as
    scanners write), and as one Siemens mosaic (the slices tiled 3 x 3, a CSA header with
    NumberOfImagesInMosaic; nibabel, the oracle, checks the file),
  * as NRRD by teem (`teem-unu make`): `space: left-posterior-superior` with negative space
    directions, as 3D Slicer writes, and in RAS,
  * as MetaImage by hand as ITK writes it (identity TransformMatrix, LPS Offset, samples
    from the patient's right to left),

and the test asserts, for every file, that `splat info` puts the marker voxel at its RAS
world position (1e-3 mm) and that `splat render` draws the identical picture (every pixel of
a 16-bit PNG equal) from an oblique view. A mirror moves the marker by tens of millimetres
and changes the picture. Then the same with an oblique affine: nibabel's NIfTI against the
NRRD teem writes and the MetaImage with a rotated TransformMatrix.

Usage: world_frame.py SPLAT    exit 1 on any difference.
"""
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import warnings

import numpy as np

warnings.filterwarnings("ignore")  # nibabel: "The DICOM readers are highly experimental"

DIMS = (12, 10, 8)  # i (R), j (A), k (S)
SPACING = np.array([1.5, 1.2, 2.0])
ORIGIN = np.array([-10.0, 20.0, -30.0])  # RAS position of voxel (0, 0, 0)
MARKER = (2, 7, 5)


def volume():
    """int16 samples indexed [i, j, k]: RAS index order."""
    d = np.zeros(DIMS, np.int16)
    d[1:9, 2:4, 1:3] = 300  # bar along +x (R) ...
    d[1:3, 2:8, 1:3] = 300  # ... and along +y (A): an L seen from above
    d[:, :, 5] += np.arange(DIMS[0], dtype=np.int16)[:, None] * 20  # ramp along x
    d[MARKER] = 1000
    return d


def ras_affine(rotation=np.eye(3)):
    a = np.eye(4)
    a[:3, :3] = rotation @ np.diag(SPACING)
    a[:3, 3] = ORIGIN
    return a


def write_nifti(folder, data, affine):
    import nibabel as nib
    out = []
    p = os.path.join(folder, "ras.nii.gz")
    nib.save(nib.Nifti1Image(data, affine), p)
    out.append(("NIfTI RAS (nibabel)", p))
    # Radiological storage: x reversed, the affine's x axis negative.
    flipped = affine.copy()
    flipped[:3, 3] = affine[:3, :3] @ [DIMS[0] - 1, 0, 0] + affine[:3, 3]
    flipped[:3, 0] = -affine[:3, 0]
    p = os.path.join(folder, "las.nii")
    nib.save(nib.Nifti1Image(np.ascontiguousarray(data[::-1]), flipped), p)
    out.append(("NIfTI x flipped (nibabel)", p))
    return out


def write_dicom(folder, data, affine):
    """One file per k; columns run to patient left (RAS -x), rows to posterior (RAS -y)."""
    import pydicom
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import ExplicitVRLittleEndian, generate_uid
    series = os.path.join(folder, "dicom")
    os.makedirs(series)
    lps = np.diag([-1.0, -1.0, 1.0])
    r = lps @ -affine[:3, 0] / SPACING[0]  # column direction (LPS): along -i
    c = lps @ -affine[:3, 1] / SPACING[1]  # row direction (LPS): along -j
    study, uid = generate_uid(), generate_uid()
    for k in range(DIMS[2]):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.4"
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = Dataset()
        ds.file_meta = meta
        ds.SOPClassUID = meta.MediaStorageSOPClassUID
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.StudyInstanceUID, ds.SeriesInstanceUID = study, uid
        ds.Modality = "MR"
        ds.InstanceNumber = DIMS[2] - k  # numbering backwards: positions must decide
        first = affine @ [DIMS[0] - 1, DIMS[1] - 1, k, 1]  # pixel (0, 0) of this slice
        ds.ImagePositionPatient = [float("%.6f" % x) for x in lps @ first[:3]]
        ds.ImageOrientationPatient = [float("%.9f" % x) for x in list(r) + list(c)]
        ds.PixelSpacing = [float(SPACING[1]), float(SPACING[0])]  # row, column spacing
        ds.SliceThickness = float(SPACING[2])
        ds.Rows, ds.Columns = DIMS[1], DIMS[0]
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit = 16, 16, 15
        ds.PixelRepresentation = 1
        # Pixel (row y, column x) is voxel (nx-1-x, ny-1-y, k).
        ds.PixelData = np.ascontiguousarray(data[::-1, ::-1, k].T).astype("<i2").tobytes()
        ds.is_little_endian, ds.is_implicit_VR = True, False
        ds.preamble = b"\0" * 128
        pydicom.dcmwrite(os.path.join(series, "slice%02d.dcm" % k), ds, write_like_original=False)
    return [("DICOM series LPS (pydicom)", series)]


def csa2(tags):
    """A Siemens CSA2 header ("SV10") holding `tags`: (name, vr, [item strings])."""
    out = b"SV10" + b"\x04\x03\x02\x01" + struct.pack("<2I", len(tags), 77)
    for name, vr, items in tags:
        n_items = max(6, len(items))
        syngodt = {"US": 10, "SH": 22, "FD": 4}[vr]  # Siemens' type codes (GDCM checks them)
        out += struct.pack("<64si4s3i", name.encode(), len(items), vr.encode(), syngodt, n_items,
                           77)
        for k in range(n_items):
            data = (items[k].encode() + b"\0") if k < len(items) else b""
            out += struct.pack("<4i", len(data), len(data), 77, len(data)) + data
            out += b"\0" * (-len(data) % 4)
    return out


def write_mosaic(folder, data, affine):
    """One Siemens mosaic: the 8 slices tiled 3 x 3 (one tile empty), as a scanner writes it."""
    import pydicom
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import ExplicitVRLittleEndian, generate_uid
    lps = np.diag([-1.0, -1.0, 1.0])
    r = lps @ -affine[:3, 0] / SPACING[0]
    c = lps @ -affine[:3, 1] / SPACING[1]
    n = lps @ affine[:3, 2] / SPACING[2]
    m = int(np.ceil(np.sqrt(DIMS[2])))
    rows, cols = DIMS[1], DIMS[0]  # one tile
    image = np.zeros((m * rows, m * cols), np.int16)
    for k in range(DIMS[2]):
        y0, x0 = (k // m) * rows, (k % m) * cols
        image[y0:y0 + rows, x0:x0 + cols] = data[::-1, ::-1, k].T
    # ImagePositionPatient is the whole mosaic's (Siemens): the first tile's first pixel moved
    # back by half the size difference (nibabel's MosaicWrapper undoes exactly this).
    first = lps @ (affine @ [DIMS[0] - 1, DIMS[1] - 1, 0, 1])[:3]
    ipp = first - c * SPACING[1] * (m * rows - rows) / 2 - r * SPACING[0] * (m * cols - cols) / 2
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.4"
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID = meta.MediaStorageSOPClassUID
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.StudyInstanceUID, ds.SeriesInstanceUID = generate_uid(), generate_uid()
    ds.Modality = "MR"
    ds.ImageType = ["ORIGINAL", "PRIMARY", "M", "MOSAIC"]
    ds.InstanceNumber = 1
    ds.ImagePositionPatient = [float("%.6f" % x) for x in ipp]
    ds.ImageOrientationPatient = [float("%.9f" % x) for x in list(r) + list(c)]
    ds.PixelSpacing = [float(SPACING[1]), float(SPACING[0])]
    ds.SpacingBetweenSlices = float(SPACING[2])
    ds.Rows, ds.Columns = image.shape
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.BitsAllocated, ds.BitsStored, ds.HighBit = 16, 16, 15
    ds.PixelRepresentation = 1
    ds.add_new(0x00290010, "LO", "SIEMENS CSA HEADER")
    ds.add_new(0x00291010, "OB", csa2([("NumberOfImagesInMosaic", "US", [str(DIMS[2])]),
                                       ("AcquisitionMatrixText", "SH", ["%dp*%d" % (rows, cols)]),
                                       ("SliceNormalVector", "FD",
                                        ["%.8f" % x for x in n])]))
    ds.PixelData = image.astype("<i2").tobytes()
    ds.is_little_endian, ds.is_implicit_VR = True, False
    ds.preamble = b"\0" * 128
    p = os.path.join(folder, "mosaic.dcm")
    pydicom.dcmwrite(p, ds, write_like_original=False)
    # The oracle: nibabel reads this file with the marker where the volume has it.
    from nibabel.nicom import dicomwrappers
    w = dicomwrappers.wrapper_from_file(p)
    got = w.get_data()
    idx = np.unravel_index(np.argmax(got), got.shape)
    pos = lps @ (w.affine @ (list(idx) + [1]))[:3]
    assert np.abs(pos - (affine @ (list(MARKER) + [1]))[:3]).max() < 1e-3, pos
    return [("DICOM Siemens mosaic (pydicom, CSA)", p)]


def vec(v):
    return "(" + ",".join("%.9g" % x for x in v) + ")"


def write_nrrd(folder, data, affine):
    raw = os.path.join(folder, "samples.raw")
    data.transpose(2, 1, 0).astype("<i2").tofile(raw)  # x fastest
    out = []
    for label, space, sign in (("NRRD LPS as 3D Slicer writes (teem)", "left-posterior-superior",
                                np.array([-1.0, -1.0, 1.0])),
                               ("NRRD RAS (teem)", "RAS", np.ones(3))):
        p = os.path.join(folder, "%s.nrrd" % space[:3])
        dirs = " ".join(vec(sign * affine[:3, a]) for a in range(3))
        subprocess.run(["teem-unu", "make", "-i", raw, "-t", "short", "-s"] +
                       [str(n) for n in DIMS] +
                       ["-e", "raw", "-en", "little", "-spc", space, "-orig",
                        vec(sign * affine[:3, 3]), "-dirs", dirs, "-o", p],
                       check=True, capture_output=True)
        out.append((label, p))
    return out


def write_metaimage(folder, data, affine):
    """As ITK writes: LPS physical space, samples stored along the TransformMatrix rows."""
    lps = np.diag([-1.0, -1.0, 1.0])
    # Store the samples with index axes i, j reversed: their directions in LPS are then
    # lps @ -axis, the identity for an axis-aligned RAS volume.
    stored = np.ascontiguousarray(data[::-1, ::-1, :])
    rows = [lps @ -affine[:3, 0] / SPACING[0], lps @ -affine[:3, 1] / SPACING[1],
            lps @ affine[:3, 2] / SPACING[2]]
    offset = lps @ (affine @ [DIMS[0] - 1, DIMS[1] - 1, 0, 1])[:3]
    p = os.path.join(folder, "itk.mha")
    header = ("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
              "CompressedData = False\nTransformMatrix = %s\nOffset = %s\n"
              "CenterOfRotation = 0 0 0\nAnatomicalOrientation = RAI\n"
              "ElementSpacing = %s\nDimSize = %s\nElementType = MET_SHORT\n"
              "ElementDataFile = LOCAL\n" %
              (" ".join("%.9g" % x for row in rows for x in row),
               " ".join("%.9g" % x for x in offset), " ".join("%.9g" % x for x in SPACING),
               " ".join(str(n) for n in DIMS)))
    with open(p, "wb") as f:
        f.write(header.encode())
        f.write(stored.transpose(2, 1, 0).astype("<i2").tobytes())
    return [("MetaImage LPS as ITK writes (by hand)", p)]


def splat_info(splat, path):
    r = subprocess.run([splat, "info", path], capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        raise RuntimeError("splat info %s: %s" % (path, r.stderr.strip()))
    for line in r.stdout.splitlines():
        if line.startswith("maximum:"):
            w = line.split("world (")[1].rstrip(")")
            return np.array([float(x) for x in w.split(",")]), r.stderr.strip()
    raise RuntimeError("splat info %s printed no maximum" % path)


def splat_render(splat, path, out, renderer):
    r = subprocess.run([splat, "render", path, "-o", out, "--mode", "mip", "--size", "48x40",
                        "--azimuth", "30", "--elevation", "20", "--renderer", renderer,
                        "--pixel-size", "0.6", "--bit-depth", "16"],
                       capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise RuntimeError("splat render %s: %s" % (path, r.stderr.strip()))
    import matplotlib.image
    return matplotlib.image.imread(out)


def check(splat, tmp, name, rotation):
    folder = os.path.join(tmp, name)
    os.makedirs(folder)
    data, affine = volume(), ras_affine(rotation)
    files = (write_nifti(folder, data, affine) + write_dicom(folder, data, affine) +
             write_mosaic(folder, data, affine) +
             write_nrrd(folder, data, affine) + write_metaimage(folder, data, affine))
    expected = (affine @ (list(MARKER) + [1]))[:3]
    failures = []
    images = {}
    for label, path in files:
        try:
            marker, warnings = splat_info(splat, path)
        except RuntimeError as e:
            failures.append("%s: %s" % (label, e))
            continue
        err = np.abs(marker - expected).max()
        status = "ok" if err <= 1e-3 else "FAIL"
        if err > 1e-3:
            failures.append("%s: marker at RAS %s, expected %s" % (label, marker, expected))
        print("%-40s marker RAS (%8.3f, %8.3f, %8.3f) off %.2g mm %s %s" %
              (label, *marker, err, status, warnings.replace("\n", " | ")[:80]))
        for renderer in ("axis", "sheet", "reference"):
            img = splat_render(splat, path, os.path.join(folder, "%d_%s.png" % (len(images), renderer)),
                               renderer)
            images.setdefault(renderer, []).append((label, img))
    for renderer, shots in images.items():
        ref_label, ref = shots[0]
        if ref.max() <= 0:
            failures.append("%s: %s renders an empty image" % (ref_label, renderer))
        # The volume is asymmetric: its mirror image differs (the check can fail).
        if np.array_equal(ref, ref[:, ::-1]):
            failures.append("%s: %s image is left-right symmetric" % (ref_label, renderer))
        for label, img in shots[1:]:
            diff = np.abs(img.astype(float) - ref.astype(float)).max()
            if diff > 2.0 / 65535:
                failures.append("%s: %s image differs from %s's by %.3g" %
                                (label, renderer, ref_label, diff))
    return failures


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    splat = sys.argv[1]
    if not shutil.which("teem-unu"):
        print("world_frame: teem-unu is not installed (tools/setup.sh: teem-apps)")
        return 1
    tmp = tempfile.mkdtemp(prefix="splat_world_frame_")
    try:
        failures = check(splat, tmp, "axis_aligned", np.eye(3))
        # Oblique: 20 degrees about an axis off every coordinate axis.
        axis = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
        t = np.radians(20.0)
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        R = np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * K @ K
        failures += check(splat, tmp, "oblique", R)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    for f in failures:
        print("FAIL: " + f)
    print("world_frame: %s" % ("%d failures" % len(failures) if failures else "every format agrees"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
