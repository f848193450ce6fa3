// Bricks read alone from files (docs/parallel.md): every brick of a
// NIfTI, NRRD, MetaImage or .raw file, raw-stored or compressed, equals the crop of the whole
// loaded volume bit for bit — several sample types, both byte orders, odd dimensions, file
// axes flipped and permuted against the world — and the background value read from the
// outer faces alone equals the one-process value.
#include <nifti/nifti1.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstddef>
#include <cstdlib>

#include "deflate_util.h"
#include "splat/bricks.h"
#include "splat/volume_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

const glm::ivec3 kFileDims(7, 6, 5);  // odd, all different

struct Type {
    const char* name;  // canonical (NRRD type, raw file name)
    int nifti;         // NIfTI datatype
    const char* meta;  // MetaImage ElementType
};
const Type kTypes[] = {{"uint8", DT_UINT8, "MET_UCHAR"},     {"int8", DT_INT8, "MET_CHAR"},
                       {"uint16", DT_UINT16, "MET_USHORT"},  {"int16", DT_INT16, "MET_SHORT"},
                       {"uint32", DT_UINT32, "MET_UINT"},    {"int32", DT_INT32, "MET_INT"},
                       {"float32", DT_FLOAT32, "MET_FLOAT"}, {"float64", DT_FLOAT64, "MET_DOUBLE"}};

/// Values that exercise the type: its sign, its range, fractions for floats (uint32 and
/// int32 beyond float's 24 bits, so the conversion rounds).
std::vector<double> valuesOf(const std::string& type, std::size_t n) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double s = std::sin(double(i) * 0.7);
        if (type == "uint8") v[i] = double((i * 37) % 256);
        if (type == "int8") v[i] = double((i * 37) % 256) - 128;
        if (type == "uint16") v[i] = double((i * 1237) % 65536);
        if (type == "int16") v[i] = double((i * 1237) % 65536) - 32768;
        if (type == "uint32") v[i] = double((std::uint64_t(i) * 2654435761u) % 4294967296u);
        if (type == "int32")
            v[i] = double(std::int64_t((i * 2654435761u) % 4294967296u) - 2147483648LL);
        if (type == "float32") v[i] = double(float(s * 1000.25));
        if (type == "float64") v[i] = s * 1e5 + 1.0 / 3.0;
    }
    return v;
}

std::string encode(const std::string& type, const std::vector<double>& v, bool big) {
    if (type == "uint8") return samples<std::uint8_t>(v, big);
    if (type == "int8") return samples<std::int8_t>(v, big);
    if (type == "uint16") return samples<std::uint16_t>(v, big);
    if (type == "int16") return samples<std::int16_t>(v, big);
    if (type == "uint32") return samples<std::uint32_t>(v, big);
    if (type == "int32") return samples<std::int32_t>(v, big);
    if (type == "float32") return samples<float>(v, big);
    return samples<double>(v, big);
}

/// File axis 0 runs along world -y (spacing 1.5), axis 1 along +z (2), axis 2 along -x (1):
/// the file's box of a brick is not the world box.
const glm::dvec3 kCol[3] = {{0, -1.5, 0}, {0, 0, 2}, {-1, 0, 0}};

template <typename T>
void put(std::string& s, std::size_t at, T value, bool big) {
    const std::string b = bytesOf(value, big);
    std::memcpy(s.data() + at, b.data(), b.size());
}

std::string niftiFile(const Type& t, const std::string& data, bool big, float slope, float inter) {
    std::string s(352, '\0');
    put<std::int32_t>(s, offsetof(nifti_1_header, sizeof_hdr), 348, big);
    const short dim[8] = {3, short(kFileDims.x), short(kFileDims.y), short(kFileDims.z), 1, 1, 1,
                          1};
    for (int d = 0; d < 8; ++d) put<short>(s, offsetof(nifti_1_header, dim) + 2 * d, dim[d], big);
    put<short>(s, offsetof(nifti_1_header, datatype), short(t.nifti), big);
    std::size_t bits = 8;
    for (const char* w : {"16", "32", "64"})
        if (std::string(t.name).find(w) != std::string::npos) bits = std::size_t(std::atoi(w));
    put<short>(s, offsetof(nifti_1_header, bitpix), short(bits), big);
    const float pixdim[4] = {1, 1.5f, 2, 1};
    for (int d = 0; d < 4; ++d)
        put<float>(s, offsetof(nifti_1_header, pixdim) + 4 * d, pixdim[d], big);
    put<float>(s, offsetof(nifti_1_header, vox_offset), 352, big);
    put<float>(s, offsetof(nifti_1_header, scl_slope), slope, big);
    put<float>(s, offsetof(nifti_1_header, scl_inter), inter, big);
    put<short>(s, offsetof(nifti_1_header, sform_code), 1, big);
    const std::size_t rows[3] = {offsetof(nifti_1_header, srow_x), offsetof(nifti_1_header, srow_y),
                                 offsetof(nifti_1_header, srow_z)};
    const double origin[3] = {10, 20, 30};
    for (int r = 0; r < 3; ++r) {
        for (int a = 0; a < 3; ++a) put<float>(s, rows[r] + 4 * a, float(kCol[a][r]), big);
        put<float>(s, rows[r] + 12, float(origin[r]), big);
    }
    std::memcpy(s.data() + offsetof(nifti_1_header, magic), "n+1", 4);
    return s + data;
}

std::string nrrdHeader(const Type& t, bool big, const std::string& encoding,
                       const std::string& extra) {
    return std::string("NRRD0004\ntype: ") + t.name +
           "\ndimension: 3\nsizes: 7 6 5\nendian: " + (big ? "big" : "little") +
           "\nencoding: " + encoding +
           "\nspace: RAS\nspace directions: (0,-1.5,0) (0,0,2) (-1,0,0)\n"
           "space origin: (10,20,30)\n" +
           extra;
}

std::string metaHeader(const Type& t, bool big, const std::string& extra,
                       const std::string& dataFile) {
    // LPS: index axis 0 along +y_LPS = -y_RAS, axis 1 along +z, axis 2 along +x_LPS = -x_RAS.
    return std::string("ObjectType = Image\nNDims = 3\nDimSize = 7 6 5\nElementType = ") + t.meta +
           "\nElementSpacing = 1.5 2 1\nTransformMatrix = 0 1 0 0 0 1 1 0 0\n" +
           "Offset = -10 -20 30\nBinaryDataByteOrderMSB = " + (big ? "True" : "False") + "\n" +
           extra + "ElementDataFile = " + dataFile + "\n";
}

std::string bzip2Of(const fs::path& dir, const std::string& bytes) {
    const fs::path in = dir / "bz_in.bin";
    writeBytes(in, bytes);
    const fs::path out = dir / "bz_in.bin.bz2";
    fs::remove(out);
    REQUIRE(std::system(("bzip2 -k -f " + in.string()).c_str()) == 0);
    std::ifstream f(out, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

/// Every brick of 5 (ghost layers 2) and a few boxes of `spec`, against the whole volume.
void checkBricks(const std::string& spec, const LoadOptions& options = {}) {
    INFO(spec);
    const Volume whole = loadVolume(spec, options);
    bool alone = false;
    const Volume g = volumeGeometry(spec, options, &alone);
    CHECK(alone);
    CHECK(g.dims == whole.dims);
    CHECK(g.spacing == whole.spacing);
    CHECK(g.origin == whole.origin);
    CHECK(g.direction == whole.direction);
    CHECK(g.background == whole.background);  // bit for bit: the same median
    CHECK(g.backgroundSource == whole.backgroundSource);
    std::vector<std::pair<glm::ivec3, glm::ivec3>> boxes;
    for (const Brick& b : splitBricks(whole.dims, 5, 2).bricks)
        boxes.emplace_back(b.loadLo, b.loadHi);
    boxes.emplace_back(glm::ivec3(0), whole.dims);
    boxes.emplace_back(glm::ivec3(1, 2, 3), glm::ivec3(2, 3, 4));
    boxes.emplace_back(glm::ivec3(0, 1, 0), whole.dims - glm::ivec3(1, 0, 2));
    for (const auto& [lo, hi] : boxes) {
        const Volume b = loadVolumeBrick(spec, options, lo, hi);
        REQUIRE(b.dims == hi - lo);
        CHECK(b.spacing == whole.spacing);
        CHECK(b.origin == whole.world(glm::dvec3(lo)));
        CHECK(b.direction == whole.direction);
        std::size_t differ = 0;
        for (int k = 0; k < b.dims.z; ++k)
            for (int j = 0; j < b.dims.y; ++j)
                for (int i = 0; i < b.dims.x; ++i) {
                    const float x = b.at(i, j, k), y = whole.at(lo.x + i, lo.y + j, lo.z + k);
                    if (std::memcmp(&x, &y, sizeof x) != 0) ++differ;
                }
        CHECK(differ == 0);
    }
}

fs::path folder(const std::string& name) {
    const fs::path dir = fs::path(SPLAT_TEST_TMP) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

const std::size_t kCount = std::size_t(kFileDims.x) * kFileDims.y * kFileDims.z;

}  // namespace

TEST_CASE("brick files: NIfTI bricks equal the crop of the whole volume", "[bricks][volume]") {
    const fs::path dir = folder("brick_files_nifti");
    // The file's permuted, flipped axes give the model dims 5 x 7 x 6 (x from file axis 2).
    for (const Type& t : kTypes)
        for (bool big : {false, true}) {
            const std::string data = encode(t.name, valuesOf(t.name, kCount), big);
            const fs::path p = dir / (std::string(t.name) + (big ? "_be" : "_le") + ".nii");
            const bool scale = std::string(t.name) == "int16" || std::string(t.name) == "uint8";
            writeBytes(p, niftiFile(t, data, big, scale ? 0.37f : 0, scale ? -3.25f : 0));
            checkBricks(p.string());
        }
    CHECK(loadVolume((dir / "int16_le.nii").string()).dims == glm::ivec3(5, 7, 6));
    // Compressed: the stream is decompressed and only the brick's bytes kept.
    for (const char* type : {"int16", "float64"}) {
        const Type& t = *std::find_if(std::begin(kTypes), std::end(kTypes),
                                      [&](const Type& x) { return std::string(x.name) == type; });
        const std::string file =
            niftiFile(t, encode(t.name, valuesOf(t.name, kCount), true), true, 0.5f, 7);
        const fs::path gz = dir / (std::string(type) + ".nii.gz");
        writeBytes(gz, deflateBytes(file, true));
        checkBricks(gz.string());
    }
}

TEST_CASE("brick files: NRRD bricks equal the crop of the whole volume", "[bricks][volume]") {
    const fs::path dir = folder("brick_files_nrrd");
    for (const Type& t : kTypes)
        for (bool big : {false, true}) {
            const std::string data = encode(t.name, valuesOf(t.name, kCount), big);
            const std::string stem = std::string(t.name) + (big ? "_be" : "_le");
            writeBytes(dir / (stem + ".nrrd"), nrrdHeader(t, big, "raw", "") + "\n" + data);
            checkBricks((dir / (stem + ".nrrd")).string());
        }
    const Type& t = kTypes[5];  // int32
    const std::string data = encode(t.name, valuesOf(t.name, kCount), true);
    // Detached raw data after a line skip and a byte skip; byte skip -1 (data at the end).
    writeBytes(dir / "skip.raw", "two lines\nof text\nXYZ" + data);
    writeBytes(dir / "skip.nhdr",
               nrrdHeader(t, true, "raw", "line skip: 2\nbyte skip: 3\ndata file: skip.raw\n"));
    checkBricks((dir / "skip.nhdr").string());
    writeBytes(dir / "end.raw", std::string(11, 'x') + data);
    writeBytes(dir / "end.nhdr", nrrdHeader(t, true, "raw", "byte skip: -1\ndata file: end.raw\n"));
    checkBricks((dir / "end.nhdr").string());
    // gzip (attached, and detached with a byte skip in the decompressed stream) and bzip2.
    writeBytes(dir / "gz.nrrd", nrrdHeader(t, true, "gzip", "") + "\n" + deflateBytes(data, true));
    checkBricks((dir / "gz.nrrd").string());
    writeBytes(dir / "gzskip.raw.gz", deflateBytes("12345" + data, false));
    writeBytes(dir / "gzskip.nhdr",
               nrrdHeader(t, true, "gzip", "byte skip: 5\ndata file: gzskip.raw.gz\n"));
    checkBricks((dir / "gzskip.nhdr").string());
    const std::string bz = bzip2Of(dir, data);
    writeBytes(dir / "bz.nrrd", nrrdHeader(t, true, "bzip2", "") + "\n" + bz + bz.substr(0, 0));
    checkBricks((dir / "bz.nrrd").string());
    // Two concatenated bzip2 streams (pbzip2 writes them).
    const std::string half = bzip2Of(dir, data.substr(0, 100));
    const std::string rest = bzip2Of(dir, data.substr(100));
    writeBytes(dir / "bz2.nrrd", nrrdHeader(t, true, "bzip2", "") + "\n" + half + rest);
    checkBricks((dir / "bz2.nrrd").string());
    // Text data is not byte addressable: loaded whole and cropped.
    std::string text;
    for (double x : valuesOf(t.name, kCount)) text += std::to_string(std::int64_t(x)) + " ";
    writeBytes(dir / "text.nrrd", nrrdHeader(t, false, "text", "") + "\n" + text);
    bool alone = true;
    const Volume g = volumeGeometry((dir / "text.nrrd").string(), {}, &alone);
    CHECK_FALSE(alone);
    CHECK(loadVolumeBrick((dir / "text.nrrd").string(), {}, glm::ivec3(1), glm::ivec3(3))
              .at(0, 0, 0) == loadVolume((dir / "text.nrrd").string()).at(1, 1, 1));
}

TEST_CASE("brick files: MetaImage and raw bricks equal the crop of the whole volume",
          "[bricks][volume]") {
    const fs::path dir = folder("brick_files_meta");
    for (const Type& t : kTypes)
        for (bool big : {false, true}) {
            const std::string data = encode(t.name, valuesOf(t.name, kCount), big);
            const std::string stem = std::string(t.name) + (big ? "_be" : "_le");
            writeBytes(dir / (stem + ".mha"), metaHeader(t, big, "", "LOCAL") + data);
            checkBricks((dir / (stem + ".mha")).string());
        }
    const Type& t = kTypes[2];  // uint16
    const std::string data = encode(t.name, valuesOf(t.name, kCount), true);
    writeBytes(dir / "sep.bin", std::string(9, 'h') + data);
    writeBytes(dir / "sep.mhd", metaHeader(t, true, "HeaderSize = 9\n", "sep.bin"));
    checkBricks((dir / "sep.mhd").string());
    writeBytes(dir / "end.mhd", metaHeader(t, true, "HeaderSize = -1\n", "sep.bin"));
    checkBricks((dir / "end.mhd").string());
    const std::string z = deflateBytes(data, false);
    writeBytes(
        dir / "z.mha",
        metaHeader(t, true,
                   "CompressedData = True\nCompressedDataSize = " + std::to_string(z.size()) + "\n",
                   "LOCAL") +
            z);
    checkBricks((dir / "z.mha").string());
    // .raw and .raw.gz: dims and type from the name, big-endian from the options.
    LoadOptions o;
    o.raw.bigEndian = true;
    o.raw.spacing = glm::dvec3(1, 1.5, 2);
    writeBytes(dir / "v_7x6x5_uint16.raw", data);
    checkBricks((dir / "v_7x6x5_uint16.raw").string(), o);
    writeBytes(dir / "v_7x6x5_uint16.raw.gz", deflateBytes(data, true));
    checkBricks((dir / "v_7x6x5_uint16.raw.gz").string(), o);
}

TEST_CASE("brick files: a background value that differs from 0 and NaN samples",
          "[bricks][volume]") {
    const fs::path dir = folder("brick_files_background");
    // A CT-like volume: -1000 on most of the faces, tissue inside and on a few face samples.
    std::vector<double> v(kCount, -1000.0);
    for (std::size_t i = 0; i < kCount; ++i)
        if (i % 5 == 0 || (i % 7 > 1 && i % 7 < 5)) v[i] = double(i % 97) * 10.0 - 300.0;
    const Type& t = kTypes[3];  // int16
    writeBytes(dir / "ct.nrrd", nrrdHeader(t, false, "raw", "") + "\n" + encode("int16", v, false));
    checkBricks((dir / "ct.nrrd").string());
    CHECK(loadVolume((dir / "ct.nrrd").string()).background != 0.0f);
    // NaN samples: dropped from the rule (error policy: the brick holding one fails), or 0.
    std::vector<double> f = valuesOf("float32", kCount);
    f[0] = std::nan("");
    f[kCount - 1] = INFINITY;
    f[40] = std::nan("");
    writeBytes(dir / "nan.nrrd",
               nrrdHeader(kTypes[6], false, "raw", "") + "\n" + encode("float32", f, false));
    LoadOptions zero;
    zero.nonFinite = NonFinitePolicy::Zero;
    checkBricks((dir / "nan.nrrd").string(), zero);
    const std::string spec = (dir / "nan.nrrd").string();
    CHECK_THROWS_WITH(loadVolumeBrick(spec, {}, glm::ivec3(0), glm::ivec3(5, 7, 6)),
                      Catch::Contains("NaN/Inf samples"));
}

TEST_CASE("brick files: truncated files fail with the loader's message", "[bricks][volume]") {
    const fs::path dir = folder("brick_files_truncated");
    const Type& t = kTypes[3];  // int16
    const std::string data = encode(t.name, valuesOf(t.name, kCount), false);
    const std::string cut = data.substr(0, data.size() - 30);
    writeBytes(dir / "cut.nrrd", nrrdHeader(t, false, "raw", "") + "\n" + cut);
    const std::string spec = (dir / "cut.nrrd").string();
    const std::string whole = errorOf([&] { loadVolume(spec); });
    CHECK(whole.find("truncated data") != std::string::npos);
    bool alone = false;
    // The faces read covers the whole file: the loader's own message.
    CHECK(errorOf([&] { volumeGeometry(spec, {}, &alone); }) == whole);
    // A brick past the end names itself; one inside the data is read.
    CHECK_THAT(errorOf([&] { loadVolumeBrick(spec, {}, glm::ivec3(0), glm::ivec3(5, 7, 6)); }),
               Catch::Contains("truncated data: the brick of samples"));
    CHECK_NOTHROW(volumeGeometry(spec, {}, &alone, false));
    // Compressed: the stream ends early, or holds more than the header says.
    writeBytes(dir / "cut_gz.nrrd",
               nrrdHeader(t, false, "gzip", "") + "\n" + deflateBytes(cut, true));
    CHECK_THAT(errorOf([&] { volumeGeometry((dir / "cut_gz.nrrd").string(), {}, &alone); }),
               Catch::Contains("truncated data"));
    writeBytes(dir / "long_gz.nrrd",
               nrrdHeader(t, false, "gzip", "") + "\n" + deflateBytes(data + "xx", true));
    CHECK_THAT(errorOf([&] { volumeGeometry((dir / "long_gz.nrrd").string(), {}, &alone); }),
               Catch::Contains("holds more data than the header declares"));
    const std::string z = deflateBytes(data, true);
    writeBytes(dir / "broken_gz.nrrd",
               nrrdHeader(t, false, "gzip", "") + "\n" + z.substr(0, z.size() / 2));
    CHECK_THAT(errorOf([&] {
                   loadVolumeBrick((dir / "broken_gz.nrrd").string(), {}, glm::ivec3(0),
                                   glm::ivec3(5, 7, 6));
               }),
               Catch::Contains("corrupt gzip data"));
}
