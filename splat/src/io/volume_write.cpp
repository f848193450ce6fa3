// Writers: NIfTI-1 (through niftilib), NRRD and MetaImage, float32 samples with spacing
// and origin. Each writes a temporary file in the destination folder and renames it,
// so a failed or interrupted write never leaves a half-written volume behind.
#include <nifti2_io.h>

#include <cstdio>
#include <cstring>
#include <sstream>

#include "splat/error.h"
#include "splat/volume_io.h"
#include "volume_detail.h"

namespace fs = std::filesystem;

namespace splat {

using detail::displayName;

namespace {

void checkWritable(const Volume& v, const std::string& path) {
    if (!v.hasSamples()) throw Error(path + ": volume has no data or inconsistent dimensions");
}

std::string fmt(double d) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", d);
    return buf;
}

// Host-order float32 bytes of the sample values (any storage); the header declares little
// endian (see volume_decode.cpp).
std::string floatBytes(const Volume& v) {
    std::string out(v.voxelCount() * sizeof(float), '\0');
    v.values(0, v.voxelCount(), reinterpret_cast<float*>(out.data()));
    return out;
}

}  // namespace

void saveNifti(const std::string& path, const Volume& v) {
    checkWritable(v, path);
    std::string ext = lowerExtension(path);
    if (ext != ".nii" && ext != ".nii.gz")
        throw Error(path + ": NIfTI output needs .nii or .nii.gz");
    fs::path target(path);
    const std::string file = target.filename().string();
    // niftilib picks compression from the name, so the temporary keeps the extension.
    AtomicFile out(target);
    const fs::path& tmp = out.temporary();
    const std::int64_t dims[8] = {3, v.dims.x, v.dims.y, v.dims.z, 1, 1, 1, 1};
    nifti_set_debug_level(0);
    nifti_image* nim = nifti_make_new_nim(dims, DT_FLOAT32, 1);
    if (!nim) throw Error(path + ": cannot create NIfTI image");
    const std::size_t floatSize = v.voxelCount() * sizeof(float);
    v.values(0, v.voxelCount(), static_cast<float*>(nim->data));
    nim->dx = nim->pixdim[1] = float(v.spacing.x);
    nim->dy = nim->pixdim[2] = float(v.spacing.y);
    nim->dz = nim->pixdim[3] = float(v.spacing.z);
    nim->xyz_units = NIFTI_UNITS_MM;
    // Axis-aligned affine in both forms: qform (identity rotation) and sform.
    nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
    nim->quatern_b = nim->quatern_c = nim->quatern_d = 0;
    nim->qfac = 1;
    nim->qoffset_x = float(v.origin.x);
    nim->qoffset_y = float(v.origin.y);
    nim->qoffset_z = float(v.origin.z);
    nim->sform_code = NIFTI_XFORM_SCANNER_ANAT;
    std::memset(&nim->sto_xyz, 0, sizeof nim->sto_xyz);
    for (int a = 0; a < 3; ++a) {
        nim->sto_xyz.m[a][a] = float(v.spacing[a]);
        nim->sto_xyz.m[a][3] = float(v.origin[a]);
    }
    nim->sto_xyz.m[3][3] = 1;
    if (nifti_set_filenames(nim, tmp.string().c_str(), 0, 1) != 0) {
        nifti_image_free(nim);
        throw Error(path + ": cannot set NIfTI file name");
    }
    nifti_image_write(nim);
    nifti_image_free(nim);
    // niftilib does not report a failed write (a full disk): the file is read back whole
    // and compared before it replaces anything (issue 23).
    nifti_image* back = nifti_image_read(tmp.string().c_str(), 1);
    const std::string expected = floatBytes(v);
    const bool whole = back && back->data && std::size_t(back->nvox) * back->nbyper == floatSize &&
                       std::memcmp(back->data, expected.data(), floatSize) == 0;
    if (back) nifti_image_free(back);
    if (!whole) throw Error(path + ": cannot write NIfTI file (the file written is incomplete)");
    out.commit();
}

void saveNrrd(const std::string& path, const Volume& v) {
    checkWritable(v, path);
    std::ostringstream h;
    h << "NRRD0004\n# written by splat\ntype: float\ndimension: 3\nspace: right-anterior-superior\n"
      << "sizes: " << v.dims.x << ' ' << v.dims.y << ' ' << v.dims.z << '\n'
      << "space directions: (" << fmt(v.spacing.x) << ",0,0) (0," << fmt(v.spacing.y) << ",0) (0,0,"
      << fmt(v.spacing.z) << ")\n"
      << "kinds: domain domain domain\nendian: little\nencoding: raw\n"
      << "space origin: (" << fmt(v.origin.x) << ',' << fmt(v.origin.y) << ',' << fmt(v.origin.z)
      << ")\n\n";
    std::string bytes = h.str() + floatBytes(v);
    writeFileAtomic(path, bytes.data(), bytes.size());
}

void saveMetaImage(const std::string& path, const Volume& v) {
    checkWritable(v, path);
    std::string ext = lowerExtension(path);
    if (ext != ".mha" && ext != ".mhd") throw Error(path + ": MetaImage output needs .mha or .mhd");
    fs::path target(path);
    fs::path rawPath = fs::path(target).replace_extension(".raw");
    std::ostringstream h;
    h << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
      << "CompressedData = False\nTransformMatrix = 1 0 0 0 1 0 0 0 1\n"
      << "Offset = " << fmt(v.origin.x) << ' ' << fmt(v.origin.y) << ' ' << fmt(v.origin.z) << '\n'
      << "ElementSpacing = " << fmt(v.spacing.x) << ' ' << fmt(v.spacing.y) << ' '
      << fmt(v.spacing.z) << '\n'
      << "DimSize = " << v.dims.x << ' ' << v.dims.y << ' ' << v.dims.z << '\n'
      << "ElementType = MET_FLOAT\n"
      << "ElementDataFile = "
      << (ext == ".mha" ? std::string("LOCAL") : rawPath.filename().string()) << '\n';
    if (ext == ".mha") {
        std::string bytes = h.str() + floatBytes(v);
        writeFileAtomic(path, bytes.data(), bytes.size());
    } else {
        // Data first, so the header never points at a missing file.
        const std::string bytes = floatBytes(v);
        writeFileAtomic(rawPath, bytes.data(), bytes.size());
        std::string header = h.str();
        writeFileAtomic(path, header.data(), header.size());
    }
}

}  // namespace splat
