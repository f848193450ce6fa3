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
    // The index-to-world affine (world = direction * (origin + S p)) in both forms: the
    // sform, and the qform from the same rotation (niftilib's matrix-to-quaternion).
    const glm::dvec3 o = v.direction * v.origin;
    std::memset(&nim->sto_xyz, 0, sizeof nim->sto_xyz);
    for (int r = 0; r < 3; ++r) {
        for (int a = 0; a < 3; ++a) nim->sto_xyz.m[r][a] = float(v.direction[a][r] * v.spacing[a]);
        nim->sto_xyz.m[r][3] = float(o[r]);
    }
    nim->sto_xyz.m[3][3] = 1;
    nim->sform_code = NIFTI_XFORM_SCANNER_ANAT;
    nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
    nifti_dmat44 q;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) q.m[r][c] = double(nim->sto_xyz.m[r][c]);
    double qb, qc, qd, qx, qy, qz, dx, dy, dz, qfac;
    nifti_dmat44_to_quatern(q, &qb, &qc, &qd, &qx, &qy, &qz, &dx, &dy, &dz, &qfac);
    nim->quatern_b = qb;
    nim->quatern_c = qc;
    nim->quatern_d = qd;
    nim->qfac = qfac;
    nim->qoffset_x = qx;
    nim->qoffset_y = qy;
    nim->qoffset_z = qz;
    if (nifti_set_filenames(nim, tmp.string().c_str(), 0, 1) != 0) {
        nifti_image_free(nim);
        throw Error(path + ": cannot set NIfTI file name");
    }
    nifti_image_write(nim);
    nifti_image_free(nim);
    // niftilib does not report a failed write (a full disk): the file is read back whole
    // and compared before it replaces anything.
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
    // World (RAS) axes and origin: direction applied (docs/design.md "World frame").
    auto vec = [](const glm::dvec3& a) {
        std::ostringstream o;
        o << '(' << fmt(a.x) << ',' << fmt(a.y) << ',' << fmt(a.z) << ')';
        return o.str();
    };
    const glm::dvec3 o = v.direction * v.origin;
    std::ostringstream h;
    h << "NRRD0004\n# written by splat\ntype: float\ndimension: 3\nspace: right-anterior-superior\n"
      << "sizes: " << v.dims.x << ' ' << v.dims.y << ' ' << v.dims.z << '\n'
      << "space directions: " << vec(v.direction[0] * v.spacing.x) << ' '
      << vec(v.direction[1] * v.spacing.y) << ' ' << vec(v.direction[2] * v.spacing.z) << '\n'
      << "kinds: domain domain domain\nendian: little\nencoding: raw\n"
      << "space origin: " << vec(o) << "\n\n";
    std::string bytes = h.str() + floatBytes(v);
    writeFileAtomic(path, bytes.data(), bytes.size());
}

void saveMetaImage(const std::string& path, const Volume& v) {
    checkWritable(v, path);
    std::string ext = lowerExtension(path);
    if (ext != ".mha" && ext != ".mhd") throw Error(path + ": MetaImage output needs .mha or .mhd");
    fs::path target(path);
    fs::path rawPath = fs::path(target).replace_extension(".raw");
    // MetaImage is LPS (ITK's physical space): RAS x and y negated; TransformMatrix row a
    // is the direction of index axis a.
    const glm::dvec3 flip(-1.0, -1.0, 1.0);
    const glm::dvec3 o = flip * (v.direction * v.origin);
    std::ostringstream h;
    h << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
      << "CompressedData = False\nTransformMatrix =";
    for (int a = 0; a < 3; ++a)
        for (int r = 0; r < 3; ++r) h << ' ' << fmt(flip[r] * v.direction[a][r]);
    h << "\nOffset = " << fmt(o.x) << ' ' << fmt(o.y) << ' ' << fmt(o.z) << '\n'
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
