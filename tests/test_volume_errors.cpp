// Bad input: every failure is a splat::Error with one line naming the file and the
// problem, and NaN/Inf samples follow the chosen policy.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "splat/volume_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;

namespace {

std::string loadError(const std::string& spec, const LoadOptions& o = {}) {
    std::string msg = errorOf([&] { loadVolume(spec, o); });
    CHECK(msg.find('\n') == std::string::npos);  // always one line
    return msg;
}

}  // namespace

TEST_CASE("load errors name the file and the problem", "[volume]") {
    auto dir = testTmpDir("volume_errors");
    auto path = [&](const char* name) { return (dir / name).string(); };

    CHECK(loadError(path("nope.nii")) == path("nope.nii") + ": no such file or folder");
    writeBytes(path("vol.xyz"), "hello world");
    CHECK_THAT(loadError(path("vol.xyz")),
               Catch::StartsWith(path("vol.xyz") + ": unknown file type '.xyz'"));

    // Truncated data and sizes that disagree with the data.
    writeBytes(path("t_4x4x4_uint8.raw"), std::string(60, '\1'));
    CHECK(loadError(path("t_4x4x4_uint8.raw")) ==
          path("t_4x4x4_uint8.raw") + ": truncated data: expected 64 bytes, found 60");
    writeBytes(path("l_2x2x2_int16.raw"), std::string(20, '\1'));
    CHECK(loadError(path("l_2x2x2_int16.raw")) ==
          path("l_2x2x2_int16.raw") +
              ": header sizes disagree with the data: expected 16 bytes, found 20");
    writeBytes(path("short.nrrd"),
               "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" +
                   std::string(10, '\0'));
    CHECK_THAT(loadError(path("short.nrrd")), Catch::Contains("expected 32 bytes, found 10"));
    writeBytes(path("short.mha"),
               "NDims = 3\nDimSize = 2 2 2\nElementType = MET_SHORT\n"
               "ElementDataFile = LOCAL\n" +
                   std::string(6, '\0'));
    CHECK_THAT(loadError(path("short.mha")), Catch::Contains("expected 16 bytes, found 6"));

    // Dimensions: zero, negative, overflowing.
    writeBytes(path("zero.nrrd"),
               "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 0 2 2\nencoding: raw\n\n");
    CHECK_THAT(loadError(path("zero.nrrd")), Catch::Contains("invalid NRRD sizes"));
    writeBytes(path("neg.mha"),
               "NDims = 3\nDimSize = 2 -2 2\nElementType = MET_UCHAR\n"
               "ElementDataFile = LOCAL\n");
    CHECK_THAT(loadError(path("neg.mha")), Catch::Contains("invalid MetaImage DimSize"));
    writeBytes(path("big_100000x100000x100000_uint8.raw"), "x");
    CHECK_THAT(loadError(path("big_100000x100000x100000_uint8.raw")), Catch::Contains("too large"));
    LoadOptions zero;
    zero.raw.dims = glm::ivec3(0, 4, 4);
    zero.raw.type = "uint8";
    writeBytes(path("plain.raw"), "x");
    CHECK_THAT(loadError(path("plain.raw"), zero), Catch::Contains("invalid dimensions 0 x 4 x 4"));
    CHECK_THAT(loadError(path("plain.raw")), Catch::Contains("raw data needs --dims and --type"));

    // Unsupported types.
    writeBytes(path("block.nrrd"), "NRRD0004\ntype: block\ndimension: 3\nsizes: 2 2 2\n\n");
    CHECK(loadError(path("block.nrrd")) == path("block.nrrd") + ": unsupported NRRD type 'block'");
    writeBytes(path("vec.mha"),
               "NDims = 3\nDimSize = 2 2 2\nElementType = MET_LONG_LONG\n"
               "ElementDataFile = LOCAL\n");
    CHECK_THAT(loadError(path("vec.mha")), Catch::Contains("unsupported MetaImage ElementType"));
    LoadOptions badType;
    badType.raw.dims = glm::ivec3(2, 2, 2);
    badType.raw.type = "complex64";
    CHECK_THAT(loadError(path("plain.raw"), badType),
               Catch::Contains("unsupported sample type 'complex64'"));

    // Corrupt gzip data.
    writeBytes(path("gz.nrrd"),
               "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\n"
               "encoding: gzip\n\n\x1f\x8b\x08\x00garbage-not-deflate");
    CHECK_THAT(loadError(path("gz.nrrd")),
               Catch::StartsWith(path("gz.nrrd") + ": corrupt gzip data"));
    writeBytes(path("gz.mha"),
               "NDims = 3\nDimSize = 2 2 2\nElementType = MET_FLOAT\n"
               "CompressedData = True\nElementDataFile = LOCAL\nnot zlib");  // corrupt on purpose
    CHECK_THAT(loadError(path("gz.mha")), Catch::Contains("corrupt gzip data"));

    // Missing detached data file, unreadable NIfTI.
    writeBytes(path("det.nhdr"),
               "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\n"
               "encoding: raw\ndata file: missing.raw\n");
    CHECK_THAT(loadError(path("det.nhdr")), Catch::Contains("missing.raw does not exist"));
    writeBytes(path("bad.nii"), std::string(400, 'z'));
    CHECK_THAT(loadError(path("bad.nii")),
               Catch::StartsWith(path("bad.nii") + ": not a readable NIfTI-1"));
    writeBytes(path("magic.nrrd"), "NOTNRRD\n");
    CHECK_THAT(loadError(path("magic.nrrd")), Catch::Contains("not a NRRD file"));
    // An empty folder is not a volume.
    std::filesystem::create_directories(dir / "empty");
    CHECK_THAT(loadError(path("empty")), Catch::Contains("no PNG/TIFF slices, DICOM files or volume files"));
}

TEST_CASE("truncated NIfTI data reports expected and found bytes", "[volume]") {
    auto dir = testTmpDir("volume_errors_nifti");
    Volume v = makeVolume({4, 4, 4}, {1, 1, 1}, "t");
    std::string p = (dir / "t.nii").string();
    saveNifti(p, v);
    std::filesystem::resize_file(p, 352 + 100);
    CHECK_THAT(loadError(p), Catch::Contains("truncated data: expected 256 bytes, found 100"));
}

TEST_CASE("NIfTI header problems: dims, type, gzip", "[volume]") {
    auto dir = testTmpDir("volume_errors_nifti_hdr");
    Volume v = makeVolume({2, 2, 2}, {1, 1, 1}, "t");
    std::string p = (dir / "h.nii").string();
    saveNifti(p, v);
    auto patch = [&](std::size_t offset, std::int16_t value) {
        std::fstream f(p, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(std::streamoff(offset));
        f.write(reinterpret_cast<const char*>(&value), 2);
    };
    patch(44, 0);  // dim[2] = 0 (dim[] starts at byte 40)
    CHECK(loadError(p) == p + ": invalid dimension 0 along axis 2");
    patch(44, 2);
    patch(70, 32);  // datatype = DT_COMPLEX64
    CHECK_THAT(loadError(p), Catch::StartsWith(p + ": unsupported NIfTI data type"));
    std::string gz = (dir / "c.nii.gz").string();
    writeBytes(gz, std::string("\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03garbage", 18) +
                       std::string(400, 'q'));
    CHECK_THAT(loadError(gz), Catch::StartsWith(gz + ": "));
}

TEST_CASE("NaN/Inf policy", "[volume]") {
    auto dir = testTmpDir("volume_nan");
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    std::string p = (dir / "n_3x2x2_float32.raw").string();
    writeBytes(p, samples<float>({0, 1, 2, 3, 4, nan, 6, inf, 8, 9, 10, -inf}));
    CHECK(loadError(p) == p + ": 3 NaN/Inf samples (first at voxel 2,1,0); use --nan-policy "
                              "zero to replace them by 0");
    LoadOptions o;
    o.nonFinite = NonFinitePolicy::Zero;
    Volume v = loadVolume(p, o);
    CHECK(v.at(2, 1, 0) == 0.0f);
    CHECK(v.at(2, 1, 1) == 0.0f);
    CHECK(v.at(1, 0, 1) == 0.0f);
    CHECK(v.at(1, 1, 1) == 10.0f);
    CHECK_THAT(v.note, Catch::Contains("3 NaN/Inf samples replaced by 0"));
    CHECK_THAT(describeVolume(v), Catch::Contains("3 NaN/Inf samples replaced by 0"));
}
