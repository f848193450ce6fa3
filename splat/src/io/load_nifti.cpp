// NIfTI-1, NIfTI-2 and ANALYZE 7.5 (.nii, .nii.gz, .hdr/.img pairs) through nifti2_io.
//
// A NIfTI-1 file is a 348-byte header (dims, datatype, pixdim, scl_slope/scl_inter and
// two index-to-world transforms: the qform quaternion and the sform affine, both in
// RAS+ millimetres) followed by the samples, x fastest; NIfTI-2 is the same with a
// 540-byte header of 64-bit fields; ANALYZE 7.5 is the 348-byte ancestor without
// orientation. niftilib's header structures, byte swapping and quaternion maths are used;
// the header values are checked here, in 64-bit arithmetic, before anything is
// allocated, and only one volume's bytes are read: a 4D file is a time series (dim[4] the
// time axis), and LoadOptions::time picks the volume (the first by default). Values go
// through the intensity scaling and the orientation (sform preferred, then qform, else
// pixdim). docs/input-files.md lists what is
// refused and what is only warned about.
#include <nifti2_io.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "sample_layout.h"
#include "splat/error.h"
#include "volume_detail.h"

namespace fs = std::filesystem;

namespace splat::detail {
namespace {

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

/// The fields we use, from any of the three header layouts, in host byte order.
struct Header {
    int version = 1;         ///< 0 = ANALYZE 7.5, 1 = NIfTI-1, 2 = NIfTI-2
    bool singleFile = true;  ///< n+1 / n+2: data in the same file after the header
    bool swapped = false;    ///< file byte order differs from the host's
    std::int64_t dim[8] = {};
    int datatype = 0, bitpix = 0;
    int intentCode = 0;  ///< NIfTI-1/2 intent_code (0 for ANALYZE)
    double pixdim[8] = {};
    double voxOffset = 0;
    double sclSlope = 0, sclInter = 0;
    int qformCode = 0, sformCode = 0;
    double quatern[3] = {}, qoffset[3] = {};
    double srow[3][4] = {};
    std::size_t headerSize() const { return version == 2 ? 540 : 348; }
};

bool isGz(const fs::path& p) { return toLower(p.extension().string()) == ".gz"; }

// Up to `n` bytes from the start of a plain or gzip file (gzread reads both).
std::string readStart(const fs::path& p, std::size_t n, const std::string& name) {
    gzFile f = gzopen(p.string().c_str(), "rb");
    if (!f) throw Error(name + ": cannot open for reading");
    std::string buf(n, '\0');
    int got = gzread(f, buf.data(), unsigned(n));
    int gzErr = 0;
    gzerror(f, &gzErr);
    gzclose(f);
    if (got < 0 || (gzErr != Z_OK && gzErr != Z_STREAM_END))
        throw Error(name + ": corrupt gzip data");
    buf.resize(std::size_t(got));
    return buf;
}

// The fields NIfTI-1, NIfTI-2 and ANALYZE 7.5 share (types differ: short/float vs
// int64/double).
template <typename H>
void copyDims(const H& n, Header& h) {
    for (int d = 0; d < 8; ++d) {
        h.dim[d] = n.dim[d];
        h.pixdim[d] = n.pixdim[d];
    }
    h.datatype = n.datatype;
    h.bitpix = n.bitpix;
    h.voxOffset = double(n.vox_offset);
}

// Scaling and both transforms (NIfTI-1 and NIfTI-2 only).
template <typename H>
void copyTransforms(const H& n, Header& h) {
    h.sclSlope = n.scl_slope;
    h.sclInter = n.scl_inter;
    h.intentCode = n.intent_code;
    h.qformCode = n.qform_code;
    h.sformCode = n.sform_code;
    const double q[6] = {n.quatern_b, n.quatern_c, n.quatern_d,
                         n.qoffset_x, n.qoffset_y, n.qoffset_z};
    for (int i = 0; i < 3; ++i) {
        h.quatern[i] = q[i];
        h.qoffset[i] = q[i + 3];
    }
    for (int i = 0; i < 4; ++i) {
        h.srow[0][i] = n.srow_x[i];
        h.srow[1][i] = n.srow_y[i];
        h.srow[2][i] = n.srow_z[i];
    }
}

Header parseHeader(const std::string& bytes, const std::string& name) {
    Header h;
    if (bytes.size() < 4) throw Error(name + ": not a NIfTI/ANALYZE file (too short)");
    std::int32_t size;
    std::memcpy(&size, bytes.data(), 4);
    const std::int32_t swappedSize = std::int32_t(__builtin_bswap32(std::uint32_t(size)));
    if (size == 540 || swappedSize == 540) {
        if (bytes.size() < sizeof(nifti_2_header))
            throw Error(name + ": not a NIfTI-2 file (shorter than its 540-byte header)");
        nifti_2_header n2;
        std::memcpy(&n2, bytes.data(), sizeof n2);
        h.swapped = size != 540;
        if (h.swapped) swap_nifti_header(&n2, 2);
        h.version = 2;
        if (std::memcmp(n2.magic, "n+2", 4) == 0)
            h.singleFile = true;
        else if (std::memcmp(n2.magic, "ni2", 4) == 0)
            h.singleFile = false;
        else
            throw Error(name + ": not a readable NIfTI-2 file (magic is not n+2 or ni2)");
        copyDims(n2, h);
        copyTransforms(n2, h);
        return h;
    }
    if (size != 348 && swappedSize != 348)
        throw Error(name + ": not a readable NIfTI-1 file (header size field is " +
                    std::to_string(size) + ", expected 348; 540 for NIfTI-2)");
    if (bytes.size() < sizeof(nifti_1_header))
        throw Error(name + ": not a NIfTI-1 file (shorter than its 348-byte header)");
    nifti_1_header n1;
    std::memcpy(&n1, bytes.data(), sizeof n1);
    h.swapped = size != 348;
    // ANALYZE 7.5 shares every field used here (dims, datatype, bitpix, pixdim, vox_offset)
    // at the same offsets, so the NIfTI-1 swap is right for both.
    if (h.swapped) swap_nifti_header(&n1, 1);
    if (std::memcmp(n1.magic, "n+1", 4) == 0) {
        h.version = 1;
        h.singleFile = true;
    } else if (std::memcmp(n1.magic, "ni1", 4) == 0) {
        h.version = 1;
        h.singleFile = false;
    } else {
        h.version = 0;
        h.singleFile = false;
    }
    copyDims(n1, h);
    if (h.version == 1) {
        copyTransforms(n1, h);  // ANALYZE has other fields there
    } else {
        // ANALYZE 7.5 as SPM writes it (and nibabel reads it): the scale factor in
        // dime.funused1 and the offset in dime.funused2, the bytes NIfTI-1 later named
        // scl_slope and scl_inter; without a usable factor, the calibration range over the
        // stored range (cal_max - cal_min) / (glmax - glmin) when both are non-zero.
        const double f1 = n1.scl_slope, f2 = n1.scl_inter;
        if (std::isfinite(f1) && f1 != 0) {
            h.sclSlope = f1;
            h.sclInter = std::isfinite(f2) ? f2 : 0.0;
        } else if (n1.glmax != n1.glmin && n1.cal_max != n1.cal_min && std::isfinite(n1.cal_max) &&
                   std::isfinite(n1.cal_min)) {
            h.sclSlope =
                (double(n1.cal_max) - double(n1.cal_min)) / (double(n1.glmax) - double(n1.glmin));
            h.sclInter = double(n1.cal_min) - h.sclSlope * double(n1.glmin);
        }
    }
    return h;
}

// The other file of a .hdr/.img pair (also .img.gz / .hdr.gz).
fs::path pairedFile(const fs::path& p, bool wantImage, const std::string& name) {
    std::string file = p.filename().string();
    std::string lower = toLower(file);
    bool gz = lower.size() > 3 && lower.compare(lower.size() - 3, 3, ".gz") == 0;
    std::string stem = file.substr(0, file.size() - (gz ? 7 : 4));
    const char* exts[] = {".img", ".img.gz", ".IMG", ".IMG.gz"};
    const char* hexts[] = {".hdr", ".hdr.gz", ".HDR", ".HDR.gz"};
    for (const char* e : wantImage ? exts : hexts) {
        fs::path c = p.parent_path() / (stem + e);
        std::error_code ec;
        if (fs::exists(c, ec)) return c;
    }
    throw Error(name + ": the " + (wantImage ? "image (.img)" : "header (.hdr)") +
                " file of this ANALYZE/NIfTI pair does not exist");
}

// `count` bytes at `offset` of a plain or gzip file, never more than the file holds.
std::vector<unsigned char> readData(const fs::path& p, std::uint64_t offset, std::uint64_t count) {
    if (!isGz(p)) return readFileRange(p, offset, count);
    const std::string name = displayName(p);
    regularFileSize(p);
    gzFile f = gzopen(p.string().c_str(), "rb");
    if (!f) throw Error(name + ": cannot open for reading");
    std::vector<unsigned char> out;
    std::vector<unsigned char> skip(1 << 16);
    std::uint64_t skipped = 0;
    int n = 1;
    while (skipped < offset && n > 0) {
        n = gzread(f, skip.data(),
                   unsigned(std::min<std::uint64_t>(skip.size(), offset - skipped)));
        if (n > 0) skipped += std::uint64_t(n);
    }
    // Grow with the data that really arrives, so a lying header cannot make us allocate.
    while (out.size() < count && n > 0) {
        std::size_t old = out.size();
        std::size_t chunk = std::size_t(std::min<std::uint64_t>(count - old, 1u << 24));
        out.resize(old + chunk);
        n = gzread(f, out.data() + old, unsigned(chunk));
        out.resize(old + std::size_t(std::max(n, 0)));
    }
    int gzErr = 0;
    const char* msg = gzerror(f, &gzErr);
    std::string reason = msg ? msg : "";
    gzclose(f);
    if (n < 0 || (gzErr != Z_OK && gzErr != Z_STREAM_END))
        throw Error(name + ": corrupt gzip data (" + reason + ")");
    if (skipped < offset || out.size() < count)
        throw Error(name + ": truncated data: expected " + std::to_string(count) +
                    " bytes, found " + std::to_string(skipped < offset ? 0 : out.size()) +
                    " (after byte " + std::to_string(offset) + ")");
    return out;
}

bool allFinite(const double* v, int n) {
    for (int i = 0; i < n; ++i)
        if (!std::isfinite(v[i])) return false;
    return true;
}

}  // namespace

namespace {

/// The header of `given` parsed and checked: where the first volume's samples are and how
/// they become the model's volume.
SampleLayout niftiParse(const fs::path& given, const LoadOptions& options) {
    std::string ext = toLower(given.extension().string());
    if (ext == ".gz") ext = toLower(given.stem().extension().string());
    // An .img names the pair's header; the header is where everything starts.
    const fs::path p = ext == ".img" ? pairedFile(given, false, displayName(given)) : given;
    const std::string name = displayName(p);
    regularFileSize(p);
    const Header h = parseHeader(readStart(p, 540, name), name);
    const char* format = h.version == 2 ? "NIfTI-2" : h.version == 1 ? "NIfTI-1" : "ANALYZE 7.5";
    std::vector<std::string> notes;
    if ((ext == ".nii") && !h.singleFile)
        throw Error(name + ": not a readable single-file NIfTI (magic is not n+1 or n+2)");
    // CIFTI-2 (intent codes 3000-3099, NIFTI_INTENT_CONNECTIVITY_*): a matrix over brain
    // structures stored along dim[5] and dim[6], dim[1..4] = 1 (nibabel's cifti2 module).
    if (h.version > 0 && h.intentCode >= 3000 && h.intentCode <= 3099)
        throw Error(name + ": not a volume: a CIFTI-2 matrix (NIfTI intent code " +
                    std::to_string(h.intentCode) + "), whose axes are brain structures, not space");

    // Dimensions: dim[0] axes, each >= 1; the product in checked 64-bit arithmetic.
    if (h.dim[0] < 1 || h.dim[0] > 7)
        throw Error(name + ": not a readable " + format +
                    " file (bad dim[0] = " + std::to_string(h.dim[0]) + ")");
    std::uint64_t volumes = 1;
    glm::ivec3 dims(1);
    for (int d = 1; d <= h.dim[0]; ++d) {
        if (h.dim[d] < 1 || h.dim[d] > 2147483647)
            throw Error(name + ": invalid dimension " + std::to_string(h.dim[d]) + " along axis " +
                        std::to_string(d));
        if (d <= 3)
            dims[d - 1] = int(h.dim[d]);
        else
            volumes = checkedMul(volumes, std::uint64_t(h.dim[d]), name);
    }
    auto type = niftiType(h.datatype);
    if (!type)
        throw Error(name + ": unsupported " + (h.version ? "NIfTI" : "ANALYZE") + " data type " +
                    nifti_datatype_string(h.datatype) +
                    " (supported: uint8, int8, int16, uint16, int32, uint32, float32, float64)");
    if (std::size_t(h.bitpix) != 8 * sampleSize(*type))
        throw Error(name + ": bitpix " + std::to_string(h.bitpix) + " does not match datatype " +
                    sampleTypeName(*type) + " (" + std::to_string(8 * sampleSize(*type)) +
                    " bits)");
    const std::size_t bytes = volumeBytes(dims, *type, name);
    checkedMul(bytes, volumes, name);  // the whole series must be addressable too
    // The time axis is dim[4]; dims 5-7 (vector components and more) keep their first entry.
    const std::uint64_t steps = h.dim[0] >= 4 ? std::uint64_t(h.dim[4]) : 1;
    const std::uint64_t step = timeStep(name, options, steps);

    // Where the samples start.
    if (!std::isfinite(h.voxOffset) || h.voxOffset < 0 || h.voxOffset > 9.0e15 ||
        h.voxOffset != std::floor(h.voxOffset))
        throw Error(name + ": invalid vox_offset " + std::to_string(h.voxOffset));
    std::uint64_t offset = std::uint64_t(h.voxOffset);
    const std::uint64_t first = offset;  // where the file's first volume starts
    offset = checkedAdd(offset, checkedMul(step, bytes, name), name);
    fs::path dataPath = p;
    if (h.singleFile) {
        const std::uint64_t minimum = h.headerSize() + 4;
        if (first < minimum)
            throw Error(name + ": vox_offset " + std::to_string(first) +
                        " lies inside the header (a single-file " + format +
                        " needs vox_offset >= " + std::to_string(minimum) + ")");
    } else {
        dataPath = pairedFile(p, true, name);
    }
    if (dataPath != p) regularFileSize(dataPath, "image file ");

    // Intensity scaling: value = scl_slope * stored + scl_inter; slope 0 means none.
    double slope = h.sclSlope, inter = h.sclInter;
    if (std::isinf(slope) || (slope != 0 && std::isfinite(slope) && !std::isfinite(inter)))
        throw Error(name + ": scl_slope " + std::to_string(slope) + " / scl_inter " +
                    std::to_string(inter) + " is not a usable intensity scaling");
    if (std::isnan(slope)) {
        notes.push_back("scl_slope is NaN: no intensity scaling applied");
        slope = 0;
    }

    // Geometry: sform, then qform, else pixdim ("method 1").
    for (int a = 1; a <= 3; ++a)
        if (!std::isfinite(h.pixdim[a]))
            throw Error(name + ": pixdim[" + std::to_string(a) + "] is " +
                        std::to_string(h.pixdim[a]) + " (must be finite)");
    glm::dvec3 t(0.0);
    glm::dmat3 M(1.0);
    std::string what;
    if (h.sformCode > 0) {
        for (int r = 0; r < 3; ++r)
            if (!allFinite(h.srow[r], 4))
                throw Error(name + ": the sform (srow_x/y/z) holds NaN or Inf");
        for (int a = 0; a < 3; ++a)
            for (int r = 0; r < 3; ++r) M[a][r] = h.srow[r][a];
        t = glm::dvec3(h.srow[0][3], h.srow[1][3], h.srow[2][3]);
        what = "sform";
    } else {
        double d[3];
        for (int a = 0; a < 3; ++a) {
            d[a] = h.pixdim[a + 1];
            const std::string axis = "pixdim[" + std::to_string(a + 1) + "]";
            if (d[a] == 0) {
                notes.push_back(axis + " is 0: spacing 1 assumed");
                d[a] = 1;
            } else if (d[a] < 0 && h.qformCode > 0) {
                notes.push_back(axis +
                                " is negative: its magnitude is used (the qform's qfac "
                                "gives the handedness)");
                d[a] = -d[a];
            } else if (d[a] < 0) {
                notes.push_back(axis + " is negative: applied as a flip of that axis");
            }
        }
        if (h.qformCode > 0) {
            if (!allFinite(h.quatern, 3) || !allFinite(h.qoffset, 3))
                throw Error(name + ": the qform (quatern_b/c/d, qoffset) holds NaN or Inf");
            const double qfac = h.pixdim[0] < 0 ? -1.0 : 1.0;
            nifti_dmat44 q =
                nifti_quatern_to_dmat44(h.quatern[0], h.quatern[1], h.quatern[2], h.qoffset[0],
                                        h.qoffset[1], h.qoffset[2], d[0], d[1], d[2], qfac);
            for (int a = 0; a < 3; ++a)
                for (int r = 0; r < 3; ++r) M[a][r] = q.m[r][a];
            t = glm::dvec3(q.m[0][3], q.m[1][3], q.m[2][3]);
            what = "qform";
        } else {
            for (int a = 0; a < 3; ++a) M[a][a] = d[a];
            what = "pixdim";
            if (h.version == 0)
                notes.push_back(
                    "ANALYZE 7.5 has no orientation: the index axes are taken as "
                    "x, y, z");
        }
    }

    SampleLayout L;
    L.file = dataPath;
    L.fileName = displayName(dataPath);
    if (isGz(dataPath)) {
        L.codec = SampleLayout::Codec::Gzip;
        L.skip = offset;
    } else {
        L.start = offset;
    }
    L.dims = dims;
    L.type = *type;
    // Host byte order is little-endian (volume_decode.cpp): a swapped header means the
    // samples are big-endian.
    L.bigEndian = h.swapped;
    if (std::isfinite(slope) && slope != 0.0 && (slope != 1.0 || inter != 0.0)) {
        L.slope = slope;
        L.inter = inter;
    }
    L.M = M;
    L.t = t;
    L.orientation = what;
    L.name = name;
    L.source =
        std::string(format) + " " + sampleTypeName(*type) + " (" + p.filename().string() + ")";
    if (options.time && steps > 1)
        L.source += ", time step " + std::to_string(step) + " of " + std::to_string(steps);
    if (!options.time && steps > 1)
        notes.insert(notes.begin(), "4D file: only the first of " + std::to_string(steps) +
                                        " volumes was loaded (--time T loads another)");
    else if (volumes > steps)
        notes.insert(notes.begin(), "5D file: only the first of " +
                                        std::to_string(volumes / steps) +
                                        " components of each time step was loaded");
    L.notes = notes;
    return L;
}

}  // namespace

std::optional<SampleLayout> niftiLayout(const fs::path& p, const LoadOptions& options) {
    return niftiParse(p, options);
}

Volume loadNifti(const fs::path& given, const LoadOptions& options) {
    const SampleLayout L = niftiParse(given, options);
    std::vector<unsigned char> data =
        readData(L.file, L.codec == SampleLayout::Codec::Gzip ? L.skip : L.start, L.sampleBytes());
    Volume v = makeVolume(L.dims, glm::dvec3(1.0), L.name);
    decodeSamples(data.data(), v.voxelCount(), L.type, L.bigEndian, v.data.data());
    if (L.scaled())
        for (float& s : v.data) s = float(L.slope * s + L.inter);
    v.source = L.source;
    applyOrientation(v, L.M, L.t, L.orientation);
    for (const std::string& n : L.notes) addNote(v, n);
    return v;
}

}  // namespace splat::detail
