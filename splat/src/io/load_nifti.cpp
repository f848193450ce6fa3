// NIfTI-1 (.nii, .nii.gz) through niftilib's nifti1_io.
//
// A NIfTI-1 file is a 348-byte header (dims, datatype, pixdim, scl_slope/scl_inter and
// two index-to-world transforms: the qform quaternion and the sform affine, both in
// RAS+ millimetres) followed by the samples, x fastest. niftilib parses the header,
// swaps bytes to the host order and handles gzip; we convert to float, apply the
// intensity scaling and the orientation (sform preferred, then qform, else pixdim).
#include <nifti1_io.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include "splat/error.h"
#include "volume_detail.h"

namespace fs = std::filesystem;

namespace splat::detail {
namespace {

struct NimDeleter {
    void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};
using NimPtr = std::unique_ptr<nifti_image, NimDeleter>;

std::optional<SampleType> niftiType(int datatype) {
    switch (datatype) {
        case DT_UINT8:
            return SampleType::U8;
        case DT_INT8:
            return SampleType::I8;
        case DT_INT16:
            return SampleType::I16;
        case DT_UINT16:
            return SampleType::U16;
        case DT_INT32:
            return SampleType::I32;
        case DT_UINT32:
            return SampleType::U32;
        case DT_FLOAT32:
            return SampleType::F32;
        case DT_FLOAT64:
            return SampleType::F64;
        default:
            return std::nullopt;
    }
}

// Total (decompressed) length of a .nii or .nii.gz file.
std::size_t contentLength(const fs::path& p, bool gz) {
    std::error_code ec;
    if (!gz) return std::size_t(fs::file_size(p, ec));
    gzFile f = gzopen(p.string().c_str(), "rb");
    if (!f) return 0;
    std::size_t total = 0;
    std::vector<char> buf(1 << 18);
    int n;
    while ((n = gzread(f, buf.data(), unsigned(buf.size()))) > 0) total += std::size_t(n);
    gzclose(f);
    return total;
}

// Checks the 348-byte header ourselves before handing the file to niftilib, which
// prints its own complaints to stderr: size field, magic, dims, data length.
void validateHeader(const fs::path& p, const std::string& name) {
    const bool gz = lowerExtension(p) == ".nii.gz";
    nifti_1_header h;
    gzFile f = gzopen(p.string().c_str(), "rb");
    if (!f) throw Error(name + ": cannot open for reading");
    int got = gzread(f, &h, sizeof h);
    int gzErr = 0;
    gzerror(f, &gzErr);
    gzclose(f);
    if (gzErr != Z_OK && gzErr != Z_STREAM_END) throw Error(name + ": corrupt gzip data");
    if (got != int(sizeof h))
        throw Error(name + ": not a NIfTI-1 file (shorter than its 348-byte header)");
    bool swapped = h.sizeof_hdr != 348;
    if (swapped) {
        swap_nifti_header(&h, 1);
        if (h.sizeof_hdr != 348)
            throw Error(name + ": not a readable NIfTI-1 file (bad header size)");
    }
    if (std::memcmp(h.magic, "n+1", 4) != 0)
        throw Error(name + ": not a readable NIfTI-1 single file (magic is not n+1)");
    if (h.dim[0] < 1 || h.dim[0] > 7)
        throw Error(
            name + ": not a readable NIfTI-1 file (bad dim[0] = " + std::to_string(h.dim[0]) + ")");
    std::uint64_t count = 1;
    for (int d = 1; d <= h.dim[0]; ++d) {
        if (h.dim[d] < 1)
            throw Error(name + ": invalid dimension " + std::to_string(h.dim[d]) + " along axis " +
                        std::to_string(d));
        count *= std::uint64_t(h.dim[d]);  // at most 7 factors below 2^15: no overflow
    }
    if (!niftiType(h.datatype))
        throw Error(name + ": unsupported NIfTI data type " + nifti_datatype_string(h.datatype) +
                    " (supported: uint8, int8, int16, uint16, int32, uint32, float32, float64)");
    std::size_t offset = std::size_t(std::max(0.0f, h.vox_offset));
    std::size_t expected = std::size_t(count) * std::size_t(h.bitpix / 8);
    std::size_t total = contentLength(p, gz);
    checkDataLength(expected, total > offset ? total - offset : 0, name, false);
}

glm::dmat3 linearPart(const mat44& m, glm::dvec3& t) {
    glm::dmat3 M;
    for (int a = 0; a < 3; ++a)
        for (int r = 0; r < 3; ++r) M[a][r] = m.m[r][a];
    t = glm::dvec3(m.m[0][3], m.m[1][3], m.m[2][3]);
    return M;
}

}  // namespace

Volume loadNifti(const fs::path& p) {
    const std::string name = displayName(p);
    std::error_code ec;
    if (!fs::exists(p, ec)) throw Error(name + ": no such file");
    validateHeader(p, name);
    nifti_set_debug_level(0);  // niftilib prints to stderr otherwise; we report ourselves
    NimPtr nim(nifti_image_read(p.string().c_str(), 0));
    if (!nim) throw Error(name + ": not a readable NIfTI-1 file (bad header or corrupt gzip data)");
    auto type = niftiType(nim->datatype);
    if (!type) throw Error(name + ": unsupported NIfTI data type");
    glm::ivec3 dims(std::max(nim->nx, 1), std::max(nim->ny, 1), std::max(nim->nz, 1));
    Volume v = makeVolume(dims, glm::dvec3(1.0), name);
    std::size_t extraVolumes = dims.x > 0 ? nim->nvox / v.voxelCount() : 1;

    if (nifti_image_load(nim.get()) < 0 || !nim->data)
        throw Error(name + ": cannot read the sample data (corrupt gzip data?)");
    decodeSamples(static_cast<const unsigned char*>(nim->data), v.voxelCount(), *type, false,
                  v.data.data());

    // Intensity scaling: value = scl_slope * stored + scl_inter; slope 0 means none.
    double slope = nim->scl_slope, inter = nim->scl_inter;
    if (std::isfinite(slope) && slope != 0.0 && std::isfinite(inter) &&
        (slope != 1.0 || inter != 0.0))
        for (float& d : v.data) d = float(slope * d + inter);

    v.source = std::string("NIfTI-1 ") + sampleTypeName(*type) + " (" + p.filename().string() + ")";
    if (extraVolumes > 1)
        v.note =
            "4D file: only the first of " + std::to_string(extraVolumes) + " volumes was loaded";

    glm::dvec3 t(0.0);
    glm::dmat3 M(1.0);
    std::string what;
    if (nim->sform_code > 0) {
        M = linearPart(nim->sto_xyz, t);
        what = "sform";
    } else if (nim->qform_code > 0) {
        M = linearPart(nim->qto_xyz, t);
        what = "qform";
    } else {
        // "Method 1" (ANALYZE-style): spacing from pixdim only, no orientation.
        for (int a = 0; a < 3; ++a)
            M[a][a] = std::abs(nim->pixdim[a + 1]) > 0 ? std::abs(nim->pixdim[a + 1]) : 1.0;
        what = "pixdim";
    }
    applyOrientation(v, M, t, what);
    return v;
}

}  // namespace splat::detail
