// Hostile files: every fault found by hand becomes a reproducer written here.
// Each must give one line naming the file and the problem (nothing allocated beyond what
// the file can hold, no over-read), or load with a stated warning in Volume::note, or load
// correctly. docs/input-files.md is the policy these tests pin down.
#include <nifti/nifti1.h>
#include <nifti/nifti2.h>
#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <limits>

#include "deflate_util.h"
#include "splat/volume_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

std::string loadError(const std::string& spec, const LoadOptions& o = {}) {
    std::string msg = errorOf([&] { loadVolume(spec, o); });
    CHECK(msg.find('\n') == std::string::npos);  // always one line
    return msg;
}

// A NIfTI-1 header: 2 x 2 x 2 int16, pixdim 1, vox_offset 352, no transform.
nifti_1_header niftiHeader() {
    nifti_1_header h;
    std::memset(&h, 0, sizeof h);
    h.sizeof_hdr = 348;
    h.dim[0] = 3;
    for (int d = 1; d <= 7; ++d) h.dim[d] = d <= 3 ? 2 : 1;
    h.datatype = DT_INT16;
    h.bitpix = 16;
    for (int d = 0; d <= 3; ++d) h.pixdim[d] = 1;
    h.vox_offset = 352;
    std::memcpy(h.magic, "n+1", 4);
    return h;
}

std::string niftiBytes(const nifti_1_header& h, const std::string& data) {
    std::string s(reinterpret_cast<const char*>(&h), sizeof h);
    s += std::string(4, '\0');  // the extension flag
    return s + data;
}

}  // namespace

TEST_CASE("hostile NIfTI headers: sizes in checked 64-bit arithmetic", "[volume][hostile]") {
    auto dir = testTmpDir("hostile_nifti");
    const std::string eight = samples<std::int16_t>(ramp(8));
    auto file = [&](const char* name, const nifti_1_header& h, const std::string& data) {
        std::string p = (dir / name).string();
        writeBytes(p, niftiBytes(h, data));
        return p;
    };
    SECTION("7 dimensions whose product wraps 2^64") {
        nifti_1_header h = niftiHeader();
        h.dim[0] = 7;
        for (int d = 1; d <= 7; ++d) h.dim[d] = 32767;  // 32767^7 wraps 2^64
        CHECK_THAT(loadError(file("wrap.nii", h, eight)),
                   Catch::Contains("wrap.nii: dimensions 32767 x 32767 x 32767 are too large"));
        // A 2 x 2 x 2 float64 first volume, 32767^4 volumes: 64 * 32767^4 bytes wrap 2^64.
        h.dim[1] = h.dim[2] = h.dim[3] = 2;
        h.datatype = DT_FLOAT64;
        h.bitpix = 64;
        CHECK_THAT(loadError(file("wrap4.nii", h, eight + eight + eight + eight)),
                   Catch::Contains("wrap4.nii: sizes overflow 64-bit arithmetic"));
    }
    SECTION("vox_offset 3.7e19 and vox_offset 0") {
        nifti_1_header h = niftiHeader();
        h.vox_offset = 3.7e19f;
        CHECK_THAT(loadError(file("off.nii", h, eight)), Catch::Contains("invalid vox_offset"));
        h.vox_offset = 0;  // inside the header: would shift the data by 2 voxels
        CHECK_THAT(loadError(file("off0.nii", h, eight)),
                   Catch::Contains("vox_offset 0 lies inside the header"));
        h.vox_offset = 352.5f;
        CHECK_THAT(loadError(file("offh.nii", h, eight)), Catch::Contains("invalid vox_offset"));
    }
    SECTION("bitpix must match datatype") {
        nifti_1_header h = niftiHeader();
        h.dim[1] = h.dim[2] = 16384;
        h.dim[3] = 1;
        h.bitpix = 0;  // was: a 368-byte file loaded as a 16384 x 16384 volume of zeros
        CHECK(loadError(file("bitpix.nii", h, eight)) ==
              (dir / "bitpix.nii").string() + ": bitpix 0 does not match datatype int16 (16 bits)");
        h.bitpix = 16;
        CHECK_THAT(loadError(file("short.nii", h, eight)),
                   Catch::Contains("truncated data: expected 536870912 bytes, found 16"));
    }
    SECTION("4D: only the first volume is read") {
        nifti_1_header h = niftiHeader();
        h.dim[0] = 4;
        h.dim[4] = 1000;  // 999 volumes missing: only the first one's 16 bytes are needed
        Volume v = loadVolume(file("4d.nii", h, eight));
        CHECK(v.data == std::vector<float>{0, 1, 2, 3, 4, 5, 6, 7});
        CHECK_THAT(v.note, Catch::Contains("4D file: only the first of 1000 volumes"));
    }
    SECTION("pixdim 0, NaN, Inf and negative; scl_slope NaN and Inf") {
        nifti_1_header h = niftiHeader();
        h.pixdim[2] = 0;
        Volume v = loadVolume(file("p0.nii", h, eight));
        CHECK(v.spacing == glm::dvec3(1, 1, 1));
        CHECK_THAT(v.note, Catch::Contains("pixdim[2] is 0: spacing 1 assumed"));
        h.pixdim[2] = std::numeric_limits<float>::quiet_NaN();
        CHECK_THAT(loadError(file("pnan.nii", h, eight)), Catch::Contains("pixdim[2] is nan"));
        h.pixdim[2] = std::numeric_limits<float>::infinity();
        CHECK_THAT(loadError(file("pinf.nii", h, eight)), Catch::Contains("pixdim[2] is inf"));
        h.pixdim[2] = -2;  // no transform: a flip of y, stated
        Volume n = loadVolume(file("pneg.nii", h, eight));
        CHECK(n.spacing == glm::dvec3(1, 2, 1));
        CHECK(n.at(0, 0, 0) == 2.0f);  // the file's row 1 comes first
        CHECK_THAT(n.note, Catch::Contains("pixdim[2] is negative: applied as a flip"));
        h.pixdim[2] = 1;
        h.scl_slope = std::numeric_limits<float>::infinity();
        CHECK_THAT(loadError(file("sinf.nii", h, eight)),
                   Catch::Contains("not a usable intensity scaling"));
        h.scl_slope = std::numeric_limits<float>::quiet_NaN();
        Volume s = loadVolume(file("snan.nii", h, eight));
        CHECK(s.data[7] == 7.0f);
        CHECK_THAT(s.note, Catch::Contains("scl_slope is NaN: no intensity scaling applied"));
    }
    SECTION("a non-finite sform is refused, not rendered") {
        nifti_1_header h = niftiHeader();
        h.sform_code = 1;
        h.srow_x[0] = h.srow_y[1] = h.srow_z[2] = 1;
        h.srow_x[3] = std::numeric_limits<float>::quiet_NaN();
        CHECK_THAT(loadError(file("snan.nii", h, eight)),
                   Catch::Contains("sform") && Catch::Contains("NaN or Inf"));
        h.srow_x[3] = std::numeric_limits<float>::infinity();
        CHECK_THAT(loadError(file("sinf.nii", h, eight)), Catch::Contains("NaN or Inf"));
    }
}

TEST_CASE("NIfTI-2 and ANALYZE 7.5", "[volume][hostile]") {
    auto dir = testTmpDir("hostile_nifti2");
    const std::string data = samples<std::int16_t>(ramp(24));
    SECTION("NIfTI-2 single file, 4 x 3 x 2, sform with 0.5 mm x") {
        nifti_2_header h;
        std::memset(&h, 0, sizeof h);
        h.sizeof_hdr = 540;
        std::memcpy(h.magic, "n+2\0\r\n\032\n", 8);
        h.datatype = DT_INT16;
        h.bitpix = 16;
        h.dim[0] = 3;
        h.dim[1] = 4;
        h.dim[2] = 3;
        h.dim[3] = 2;
        for (int d = 4; d < 8; ++d) h.dim[d] = 1;
        for (int d = 0; d < 4; ++d) h.pixdim[d] = 1;
        h.vox_offset = 544;
        h.scl_slope = 2;
        h.scl_inter = 1;
        h.sform_code = 1;
        h.srow_x[0] = 0.5;
        h.srow_y[1] = 1;
        h.srow_z[2] = 3;
        h.srow_z[3] = -7;
        std::string bytes(reinterpret_cast<const char*>(&h), sizeof h);
        bytes += std::string(4, '\0') + data;
        writeBytes(dir / "v2.nii", bytes);
        Volume v = loadVolume((dir / "v2.nii").string());
        REQUIRE(v.dims == glm::ivec3(4, 3, 2));
        CHECK(v.spacing == glm::dvec3(0.5, 1, 3));
        CHECK(v.origin == glm::dvec3(0, 0, -7));
        CHECK(v.data[23] == 2.0f * 23 + 1);
        CHECK_THAT(v.source, Catch::Contains("NIfTI-2 int16"));
        writeBytes(dir / "v2.nii.gz", deflateBytes(bytes, true));
        CHECK(loadVolume((dir / "v2.nii.gz").string()).data == v.data);
    }
    SECTION("ANALYZE 7.5 .hdr/.img pair, big-endian") {
        nifti_1_header h = niftiHeader();
        std::memset(h.magic, 0, 4);
        h.dim[1] = 4;
        h.dim[2] = 3;
        h.dim[3] = 2;
        h.pixdim[1] = 2;
        h.vox_offset = 0;
        // Big-endian header: swap every field used (ANALYZE from a SPARC workstation).
        nifti_1_header be = h;
        auto swap16 = [](short& v) { v = short(__builtin_bswap16(std::uint16_t(v))); };
        auto swap32f = [](float& v) {
            std::uint32_t u;
            std::memcpy(&u, &v, 4);
            u = __builtin_bswap32(u);
            std::memcpy(&v, &u, 4);
        };
        be.sizeof_hdr = int(__builtin_bswap32(348u));
        for (short& d : be.dim) swap16(d);
        swap16(be.datatype);
        swap16(be.bitpix);
        for (float& p : be.pixdim) swap32f(p);
        swap32f(be.vox_offset);
        writeBytes(dir / "a.hdr", std::string(reinterpret_cast<const char*>(&be), sizeof be));
        writeBytes(dir / "a.img", samples<std::int16_t>(ramp(24), true));
        for (const char* name : {"a.hdr", "a.img"}) {
            Volume v = loadVolume((dir / name).string());
            REQUIRE(v.dims == glm::ivec3(4, 3, 2));
            CHECK(v.spacing == glm::dvec3(2, 1, 1));
            CHECK(v.data[23] == 23.0f);
            CHECK_THAT(v.source, Catch::Contains("ANALYZE 7.5 int16"));
            CHECK_THAT(v.note, Catch::Contains("ANALYZE 7.5 has no orientation"));
        }
        fs::remove(dir / "a.img");
        CHECK_THAT(loadError((dir / "a.hdr").string()), Catch::Contains("does not exist"));
    }
    SECTION("ANALYZE 7.5 with the SPM scale factor (funused1) and offset (funused2)") {
        // nibabel 5.0 (Spm2AnalyzeImage, what nibabel.load picks) reads voxel 23 of this
        // pair as 0.25 * 23 + 3 = 8.75; then the calibration-range fallback: with funused1
        // 0, (cal_max - cal_min) / (glmax - glmin) = 10 / 100 and cal_min - 0.1 * glmin.
        nifti_1_header h = niftiHeader();
        std::memset(h.magic, 0, 4);
        h.dim[1] = 4;
        h.dim[2] = 3;
        h.dim[3] = 2;
        h.vox_offset = 0;
        h.scl_slope = 0.25f;  // dime.funused1 in ANALYZE 7.5
        h.scl_inter = 3.0f;   // dime.funused2
        writeBytes(dir / "s.hdr", std::string(reinterpret_cast<const char*>(&h), sizeof h));
        writeBytes(dir / "s.img", data);
        CHECK(loadVolume((dir / "s.hdr").string()).data[23] == 0.25f * 23 + 3);
        h.scl_slope = 0;
        h.scl_inter = 0;
        h.cal_min = 5;
        h.cal_max = 15;
        h.glmin = 20;
        h.glmax = 120;
        writeBytes(dir / "s.hdr", std::string(reinterpret_cast<const char*>(&h), sizeof h));
        CHECK(loadVolume((dir / "s.hdr").string()).data[23] == Approx(0.1 * 23 + 5 - 0.1 * 20));
    }
}

TEST_CASE("hostile raw: header bytes that wrap, .raw.gz", "[volume][hostile]") {
    auto dir = testTmpDir("hostile_raw");
    const std::string p = (dir / "v_2x2x2_uint8.raw").string();
    writeBytes(p, samples<std::uint8_t>(ramp(8)));
    LoadOptions o;
    o.raw.headerBytes = 18446744073709550616ull;  // 2^64 - 1000: the sum is checked, not read
    CHECK_THAT(loadError(p, o),
               Catch::Contains("truncated data: expected 18446744073709550624 bytes, found 8"));
    o.raw.headerBytes = std::numeric_limits<std::size_t>::max();  // CLI11's "-1"
    CHECK_THAT(loadError(p, o), Catch::Contains("overflow"));
    o.raw.headerBytes = 8;
    CHECK_THAT(loadError(p, o), Catch::Contains("truncated data: expected 16 bytes, found 8"));
    // The CLI refuses a negative --header-bytes before the library sees it.
    RunResult r = runSplat({"info", p, "--header-bytes", "-1"});
    CHECK(r.status != 0);
    CHECK_THAT(r.err, Catch::Contains("--header-bytes"));

    // .raw.gz: by name, with a header inside the compressed stream, capped inflation.
    writeBytes(dir / "g_4x3x2_int16.raw.gz", deflateBytes(samples<std::int16_t>(ramp(24)), true));
    Volume g = loadVolume((dir / "g_4x3x2_int16.raw.gz").string());
    REQUIRE(g.dims == glm::ivec3(4, 3, 2));
    CHECK(g.data[23] == 23.0f);
    CHECK_THAT(g.source, Catch::Contains("gzip"));
    writeBytes(dir / "bomb_2x2x2_uint8.raw.gz", deflateBytes(std::string(50'000'000, '\0'), true));
    CHECK_THAT(loadError((dir / "bomb_2x2x2_uint8.raw.gz").string()),
               Catch::Contains("more data than the header declares (8 bytes)"));
}

TEST_CASE("hostile NRRD and MetaImage: data checked before allocating", "[volume][hostile]") {
    auto dir = testTmpDir("hostile_nrrd");
    auto path = [&](const char* name) { return (dir / name).string(); };
    using clock = std::chrono::steady_clock;
    SECTION("a 101-byte header declaring 4.3 GB fails at once") {
        writeBytes(path("huge.mha"),
                   "NDims = 3\nDimSize = 2048 2048 1024\nElementType = MET_UCHAR\n"
                   "ElementDataFile = LOCAL\nxyz");
        writeBytes(path("huge.nrrd"),
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2048 2048 1024\n"
                   "encoding: raw\n\nxyz");
        writeBytes(path("huge_2048x2048x1024_uint8.raw"), "xyz");
        for (const char* name : {"huge.mha", "huge.nrrd", "huge_2048x2048x1024_uint8.raw"}) {
            auto t0 = clock::now();
            CHECK_THAT(loadError(path(name)),
                       Catch::Contains("truncated data: expected 4294967296 bytes, found 3"));
            // No 4 GB allocation and zero-fill first (that took 22 s): well under a second.
            CHECK(std::chrono::duration<double>(clock::now() - t0).count() < 2.0);
        }
    }
    SECTION("gzip inflation stops at the declared size") {
        const std::string bomb = deflateBytes(std::string(100'000'000, '\0'), true);  // ~100 kB
        writeBytes(path("bomb.nrrd"),
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\n"
                   "encoding: gzip\n\n" +
                       bomb);
        writeBytes(path("bomb.mha"),
                   "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nCompressedData = True\n"
                   "ElementDataFile = LOCAL\n" +
                       bomb);
        for (const char* name : {"bomb.nrrd", "bomb.mha"})
            CHECK_THAT(loadError(path(name)),
                       Catch::Contains("more data than the header declares (8 bytes)"));
    }
    SECTION("NRRD spacings and endian") {
        const std::string head = "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\n";
        const std::string data = samples<std::int16_t>(ramp(8));
        auto nrrd = [&](const char* name, const std::string& fields) {
            writeBytes(path(name), head + fields + "encoding: raw\n\n" + data);
            return path(name);
        };
        CHECK_THAT(loadError(nrrd("inf.nrrd", "endian: little\nspacings: 1 inf 1\n")),
                   Catch::Contains("invalid NRRD spacings"));
        Volume n = loadVolume(nrrd("nan.nrrd", "endian: little\nspacings: 1 nan 2\n"));
        CHECK(n.spacing == glm::dvec3(1, 1, 2));
        CHECK_THAT(n.note, Catch::Contains("spacing of axis 1 is NaN (unknown): 1 assumed"));
        Volume f = loadVolume(nrrd("neg.nrrd", "endian: little\nspacings: -2 1 1\n"));
        CHECK(f.spacing == glm::dvec3(2, 1, 1));
        CHECK(f.at(0, 0, 0) == 1.0f);  // the flip is kept: the file's x = 1 comes first
        CHECK(f.origin.x == -2.0);
        CHECK_THAT(loadError(nrrd("few.nrrd", "endian: little\nspacings: 1 2\n")),
                   Catch::Contains("'spacings' has 2 entries, dimension is 3"));
        CHECK_THAT(loadError(nrrd("both.nrrd",
                                  "endian: little\nspacings: 1 1 1\n"
                                  "space directions: (1,0,0) (0,1,0) (0,0,1)\n")),
                   Catch::Contains("both 'spacings' and 'space directions'"));
        Volume le = loadVolume(nrrd("noendian.nrrd", ""));
        CHECK(le.data[7] == 7.0f);
        CHECK_THAT(le.note, Catch::Contains("no 'endian' field: little-endian assumed for its "
                                            "2-byte samples"));
        CHECK_THAT(loadError(nrrd("nanorigin.nrrd", "endian: little\nspace origin: (0,nan,0)\n")),
                   Catch::Contains("nanorigin.nrrd: NRRD space origin '(0,nan,0)' is not finite"));
    }
    SECTION("NRRD text values must fit the type") {
        for (const char* value : {"1.7", "-5", "300", "nan"}) {
            writeBytes(path("t.nrrd"),
                       std::string("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 1 1\n"
                                   "encoding: text\n\n1 ") +
                           value + "\n");
            CHECK_THAT(loadError(path("t.nrrd")),
                       Catch::Contains("text sample 1 ('" + std::string(value) +
                                       "') is not a uint8 value"));
        }
        writeBytes(path("ok.nrrd"),
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 1 1\n"
                   "encoding: text\n\n0 255\n");
        CHECK(loadVolume(path("ok.nrrd")).data == std::vector<float>{0, 255});
    }
    SECTION("MetaImage spacing, matrix and orientation") {
        const std::string data = samples<std::uint8_t>(ramp(8));
        auto mha = [&](const char* name, const std::string& fields) {
            writeBytes(path(name), "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n" +
                                       fields + "ElementDataFile = LOCAL\n" + data);
            return path(name);
        };
        CHECK_THAT(loadError(mha("sp.mha", "ElementSpacing = 1 2\n")),
                   Catch::Contains("ElementSpacing has 2 entries, NDims is 3"));
        CHECK_THAT(loadError(mha("tm.mha", "TransformMatrix = 1 0 0 0 1 0\n")),
                   Catch::Contains("TransformMatrix has 6 entries, NDims 3 needs 9"));
        Volume ok = loadVolume(mha("rai.mha", "AnatomicalOrientation = RAI\n"));
        CHECK(ok.note.empty());
        Volume w = loadVolume(mha("lps.mha", "AnatomicalOrientation = LPS\n"));
        CHECK_THAT(w.note, Catch::Contains("AnatomicalOrientation LPS disagrees"));
        CHECK_THAT(loadError(mha("bad.mha", "AnatomicalOrientation = XYZ\n")),
                   Catch::Contains("invalid MetaImage AnatomicalOrientation 'XYZ'"));
    }
}

TEST_CASE("data files stay in the header's folder unless allowed", "[volume][hostile]") {
    auto root = testTmpDir("hostile_paths");
    fs::create_directories(root / "hdr" / "sub");
    writeBytes(root / "secret.raw", samples<std::uint8_t>(ramp(8)));
    writeBytes(root / "hdr" / "sub" / "in.raw", samples<std::uint8_t>(ramp(8)));
    const std::string head = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n";
    const std::string mhead = "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n";
    const std::string abs = (root / "secret.raw").string();
    struct Case {
        std::string name, text;
        bool inside;
    };
    const std::vector<Case> cases = {
        {"abs.nhdr", head + "data file: " + abs + "\n", false},
        {"up.nhdr", head + "data file: ../secret.raw\n", false},
        {"updown.nhdr", head + "data file: sub/../../secret.raw\n", false},
        {"in.nhdr", head + "data file: sub/in.raw\n", true},
        {"in2.nhdr", head + "data file: ./sub/../sub/in.raw\n", true},
        {"abs.mhd", mhead + "ElementDataFile = " + abs + "\n", false},
        {"up.mhd", mhead + "ElementDataFile = ../secret.raw\n", false},
        {"in.mhd", mhead + "ElementDataFile = sub/in.raw\n", true},
    };
    LoadOptions allow;
    allow.allowOutsideDataFiles = true;
    // The file's last sample (value 7): MetaImage is LPS, its x and y flip into RAS.
    auto last = [](const Volume& v, const std::string& p) {
        return p.ends_with(".mhd") ? v.at(0, 0, 1) : v.at(1, 1, 1);
    };
    for (const Case& c : cases) {
        const std::string p = (root / "hdr" / c.name).string();
        writeBytes(p, c.text);
        INFO(c.name);
        if (c.inside) {
            CHECK(last(loadVolume(p), p) == 7.0f);
        } else {
            CHECK_THAT(loadError(p), Catch::StartsWith(p + ": data file '") &&
                                         Catch::Contains("is outside the header's folder"));
            CHECK(last(loadVolume(p, allow), p) == 7.0f);
        }
    }
    // The CLI flag.
    const std::string up = (root / "hdr" / "up.nhdr").string();
    RunResult r = runSplat({"info", up});
    CHECK(r.status != 0);
    CHECK_THAT(r.err, Catch::Contains("--allow-outside-data"));
    r = runSplat({"info", up, "--allow-outside-data"});
    CHECK(r.status == 0);
}

TEST_CASE("FIFOs are refused, never opened", "[volume][hostile]") {
    auto dir = testTmpDir("hostile_fifo");
    const fs::path fifo = dir / "pipe_2x2x2_uint8.raw";
    REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
    // Opening a FIFO for reading blocks until a writer comes: a refusal proves we never did.
    CHECK_THAT(loadError(fifo.string()), Catch::Contains("not a regular file"));
    const fs::path nii = dir / "pipe.nii";
    REQUIRE(mkfifo(nii.c_str(), 0600) == 0);
    CHECK_THAT(loadError(nii.string()), Catch::Contains("not a regular file"));
    REQUIRE(mkfifo((dir / "data.raw").c_str(), 0600) == 0);
    writeBytes(dir / "d.nhdr",
               "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\n"
               "encoding: raw\ndata file: data.raw\n");
    CHECK_THAT(loadError((dir / "d.nhdr").string()),
               Catch::Contains("data file") && Catch::Contains("not a regular file"));
    writeBytes(dir / "d.mhd",
               "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
               "ElementDataFile = data.raw\n");
    CHECK_THAT(loadError((dir / "d.mhd").string()), Catch::Contains("not a regular file"));
    CHECK_THAT(loadError("/dev/zero"), Catch::Contains("not a regular file"));
}
