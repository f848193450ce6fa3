// Every loader on files written here by hand: NIfTI with scaling and a flipped/permuted
// or oblique sform, NRRD (attached, detached .nhdr, gzip, big-endian, text, space
// directions), MetaImage (.mhd/.mha, compressed, MSB), raw by name and by options,
// PNG slice folders in natural order and a DICOM series.
#include <OpenImageIO/imageio.h>
#include <nifti/nifti1.h>
#include <zlib.h>

#include <catch2/catch.hpp>
#include <cmath>

#include "deflate_util.h"
#include "splat/volume_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

// A NIfTI-1 single-file image with int16 samples, scaling and the given sform rows.
std::string niftiFile(glm::ivec3 dims, const std::vector<double>& values, float slope, float inter,
                      const float srow[3][4], int sformCode = 1) {
    nifti_1_header h;
    std::memset(&h, 0, sizeof h);
    h.sizeof_hdr = 348;
    h.dim[0] = 3;
    h.dim[1] = short(dims.x);
    h.dim[2] = short(dims.y);
    h.dim[3] = short(dims.z);
    h.dim[4] = h.dim[5] = h.dim[6] = h.dim[7] = 1;
    h.datatype = 4;  // DT_INT16
    h.bitpix = 16;
    h.pixdim[0] = 1;
    for (int a = 0; a < 3; ++a)
        h.pixdim[a + 1] =
            std::sqrt(srow[0][a] * srow[0][a] + srow[1][a] * srow[1][a] + srow[2][a] * srow[2][a]);
    h.vox_offset = 352;
    h.scl_slope = slope;
    h.scl_inter = inter;
    h.sform_code = short(sformCode);
    h.xyzt_units = 2;  // mm
    std::memcpy(h.srow_x, srow[0], sizeof h.srow_x);
    std::memcpy(h.srow_y, srow[1], sizeof h.srow_y);
    std::memcpy(h.srow_z, srow[2], sizeof h.srow_z);
    std::memcpy(h.magic, "n+1\0", 4);
    std::string s(reinterpret_cast<const char*>(&h), sizeof h);
    s += std::string(4, '\0');  // no extensions
    return s + samples<std::int16_t>(values);
}

}  // namespace

TEST_CASE("NIfTI: scl_slope/scl_inter and a flipped, permuted sform", "[volume]") {
    auto dir = testTmpDir("volume_nifti");
    const glm::ivec3 fd(4, 3, 2);  // file dims
    auto f = [](int i, int j, int k) { return double(i + 10 * j + 100 * k); };
    std::vector<double> values;
    for (int k = 0; k < fd.z; ++k)
        for (int j = 0; j < fd.y; ++j)
            for (int i = 0; i < fd.x; ++i) values.push_back(f(i, j, k));
    // File axis i -> world -y (2 mm), j -> world +z (3 mm), k -> world +x (1.5 mm).
    const float srow[3][4] = {{0, 0, 1.5f, 10}, {-2, 0, 0, 20}, {0, 3, 0, 30}};
    writeBytes(dir / "perm.nii", niftiFile(fd, values, 2.0f, 1.0f, srow));

    Volume v = loadVolume((dir / "perm.nii").string());
    REQUIRE(v.dims == glm::ivec3(fd.z, fd.x, fd.y));
    CHECK(v.spacing == glm::dvec3(1.5, 2.0, 3.0));
    // New origin: the world position of file voxel (nx-1, 0, 0), which becomes (0,0,0).
    CHECK(v.origin.x == Approx(10.0));
    CHECK(v.origin.y == Approx(20.0 - 2.0 * (fd.x - 1)));
    CHECK(v.origin.z == Approx(30.0));
    for (int k = 0; k < fd.z; ++k)
        for (int j = 0; j < fd.y; ++j)
            for (int i = 0; i < fd.x; ++i)
                REQUIRE(v.at(k, fd.x - 1 - i, j) == float(2.0 * f(i, j, k) + 1.0));
    CHECK(v.note.empty());
    CHECK_THAT(v.source, Catch::Contains("NIfTI-1 int16"));

    SECTION("slope 0 means no scaling") {
        const float id[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
        writeBytes(dir / "noscale.nii", niftiFile(fd, values, 0.0f, 5.0f, id));
        Volume w = loadVolume((dir / "noscale.nii").string());
        CHECK(w.at(3, 2, 1) == float(f(3, 2, 1)));
    }
    SECTION("an oblique sform is kept as the volume's direction") {
        const double a = 10.0 * M_PI / 180.0;
        const float c = float(std::cos(a)), s = float(std::sin(a));
        const float rot[3][4] = {{c, -s, 0, 5}, {s, c, 0, -7}, {0, 0, 1, 9}};
        writeBytes(dir / "oblique.nii", niftiFile(fd, values, 1.0f, 0.0f, rot));
        Volume w = loadVolume((dir / "oblique.nii").string());
        CHECK(w.dims == fd);
        CHECK(w.note.empty());
        REQUIRE(w.rotated());
        // Every voxel where the sform puts it.
        for (int k = 0; k < fd.z; ++k)
            for (int j = 0; j < fd.y; ++j)
                for (int i = 0; i < fd.x; ++i) {
                    const glm::dvec3 sform(c * i - s * j + 5, s * i + c * j - 7, k + 9);
                    CHECK(glm::length(w.worldPosition(glm::dvec3(i, j, k)) - sform) < 1e-5);
                }
    }
}

TEST_CASE("NRRD: attached raw, big-endian, space directions and origin", "[volume]") {
    auto dir = testTmpDir("volume_nrrd");
    std::string header =
        "NRRD0004\n# a comment\ntype: short\ndimension: 3\nspace: left-posterior-superior\n"
        "sizes: 3 2 2\nspace directions: (0.5,0,0) (0,-0.75,0) (0,0,2)\n"
        "kinds: domain domain domain\nendian: big\nencoding: raw\n"
        "space origin: (1,2,3)\nmy key:=my value\n\n";
    writeBytes(dir / "be.nrrd", header + samples<std::int16_t>(ramp(12), true));
    Volume v = loadVolume((dir / "be.nrrd").string());
    REQUIRE(v.dims == glm::ivec3(3, 2, 2));
    CHECK(v.spacing == glm::dvec3(0.5, 0.75, 2.0));
    // LPS -> RAS: the directions become (-0.5,0,0) (0,0.75,0) (0,0,2) from (-1,-2,3), so x
    // is flipped: the new first column is the file's last, at RAS (-1 - 2 * 0.5, -2, 3).
    CHECK(v.origin == glm::dvec3(-2.0, -2.0, 3.0));
    CHECK(v.at(0, 0, 0) == 2.0f);
    CHECK(v.at(2, 1, 1) == 9.0f);
    CHECK_THAT(v.source, Catch::Contains("NRRD int16"));
}

TEST_CASE("NRRD: detached .nhdr with gzip data, spacings, type aliases", "[volume]") {
    auto dir = testTmpDir("volume_nhdr");
    fs::create_directories(dir / "data");
    std::vector<double> values = ramp(24);
    writeBytes(dir / "data" / "vol.raw.gz", deflateBytes(samples<float>(values), true));
    writeBytes(dir / "vol.nhdr",
               "NRRD0005\ntype: float\ndimension: 3\nsizes: 4 3 2\nspacings: 1 2 3\n"
               "encoding: gzip\nendian: little\ndata file: data/vol.raw.gz\n");
    Volume v = loadVolume((dir / "vol.nhdr").string());
    REQUIRE(v.dims == glm::ivec3(4, 3, 2));
    CHECK(v.spacing == glm::dvec3(1, 2, 3));
    for (std::size_t i = 0; i < values.size(); ++i) REQUIRE(v.data[i] == float(values[i]));

    for (const char* type : {"unsigned char", "uchar", "uint8", "signed char", "int8_t"}) {
        writeBytes(dir / "t.nrrd", std::string("NRRD0004\ntype: ") + type +
                                       "\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" +
                                       samples<std::uint8_t>(ramp(8)));
        CHECK(loadVolume((dir / "t.nrrd").string()).data[7] == 7.0f);
    }
    writeBytes(dir / "text.nrrd",
               "NRRD0004\ntype: double\ndimension: 3\nsizes: 2 1 2\nencoding: text\n\n"
               "1.5 2.5\n-3 4e1\n");
    Volume t = loadVolume((dir / "text.nrrd").string());
    CHECK(t.data == std::vector<float>{1.5f, 2.5f, -3.0f, 40.0f});
    writeBytes(dir / "us.nrrd",
               "NRRD0004\ntype: unsigned short int\ndimension: 3\nsizes: 2 2 1\nendian: little\n"
               "encoding: raw\n\n" +
                   samples<std::uint16_t>({1, 60000, 3, 4}));
    CHECK(loadVolume((dir / "us.nrrd").string()).data[1] == 60000.0f);
}

TEST_CASE("MetaImage: .mhd with separate data, compressed .mha, MSB", "[volume]") {
    auto dir = testTmpDir("volume_meta");
    std::vector<double> values = ramp(30);
    writeBytes(dir / "vol.img", samples<std::int16_t>(values, true));
    writeBytes(dir / "vol.mhd",
               "ObjectType = Image\nNDims = 3\nDimSize = 5 3 2\nElementType = MET_SHORT\n"
               "ElementSpacing = 0.5 0.5 1.5\nOffset = -1 -2 -3\nBinaryDataByteOrderMSB = True\n"
               "ElementDataFile = vol.img\n");
    Volume v = loadVolume((dir / "vol.mhd").string());
    REQUIRE(v.dims == glm::ivec3(5, 3, 2));
    CHECK(v.spacing == glm::dvec3(0.5, 0.5, 1.5));
    // MetaImage is LPS (ITK): Offset (-1,-2,-3) is RAS (1,2,-3) and the identity matrix's x
    // and y run to RAS -x, -y, so both are flipped: RAS origin (1 - 4 * 0.5, 2 - 2 * 0.5, -3).
    CHECK(v.origin == glm::dvec3(-1, 1, -3));
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 5; ++i)
                REQUIRE(v.at(i, j, k) == float(values[std::size_t((k * 3 + 2 - j) * 5 + 4 - i)]));

    std::string packed = deflateBytes(samples<double>(values), false);
    writeBytes(dir / "c.mha",
               "ObjectType = Image\nNDims = 3\nDimSize = 5 3 2\n"
               "ElementType = MET_DOUBLE\nCompressedData = True\n"
               "CompressedDataSize = " +
                   std::to_string(packed.size()) + "\nElementDataFile = LOCAL\n" + packed);
    Volume c = loadVolume((dir / "c.mha").string());
    REQUIRE(c.dims == glm::ivec3(5, 3, 2));
    CHECK(c.at(0, 0, 1) == 29.0f);  // file sample (4, 2, 1): x and y flipped (LPS)
    CHECK_THAT(c.source, Catch::Contains("compressed"));

    for (const char* t :
         {"MET_UCHAR", "MET_CHAR", "MET_USHORT", "MET_INT", "MET_UINT", "MET_FLOAT"}) {
        std::string type = t;
        std::string data = type == "MET_UCHAR"    ? samples<std::uint8_t>(ramp(8))
                           : type == "MET_CHAR"   ? samples<std::int8_t>(ramp(8))
                           : type == "MET_USHORT" ? samples<std::uint16_t>(ramp(8))
                           : type == "MET_INT"    ? samples<std::int32_t>(ramp(8))
                           : type == "MET_UINT"   ? samples<std::uint32_t>(ramp(8))
                                                  : samples<float>(ramp(8));
        writeBytes(dir / "t.mha", "NDims = 3\nDimSize = 2 2 2\nElementType = " + type +
                                      "\nElementDataFile = LOCAL\n" + data);
        CHECK(loadVolume((dir / "t.mha").string()).at(0, 0, 1) == 7.0f);
    }
}

TEST_CASE("raw: dimensions and type from the name or from options", "[volume]") {
    auto dir = testTmpDir("volume_raw");
    writeBytes(dir / "skull_4x3x2_uint8.raw", samples<std::uint8_t>(ramp(24)));
    Volume v = loadVolume((dir / "skull_4x3x2_uint8.raw").string());
    CHECK(v.dims == glm::ivec3(4, 3, 2));
    CHECK(v.at(3, 2, 1) == 23.0f);
    CHECK(v.spacing == glm::dvec3(1.0));

    writeBytes(dir / "ct_2x2x2_int16.raw", samples<std::int16_t>({-5, 1, 2, 3, 4, 5, 6, 7}));
    CHECK(loadVolume((dir / "ct_2x2x2_int16.raw").string()).data[0] == -5.0f);
    writeBytes(dir / "f_2x1x1_f32.raw", samples<float>({0.25, 8}));
    CHECK(loadVolume((dir / "f_2x1x1_f32.raw").string()).data[1] == 8.0f);

    // Options: big-endian float with a 16-byte header and anisotropic spacing.
    writeBytes(dir / "data.raw", std::string(16, 'H') + samples<float>({1, 2, 3, 4, 5, 6}, true));
    LoadOptions o;
    o.raw.dims = glm::ivec3(3, 2, 1);
    o.raw.type = "float";
    o.raw.spacing = glm::dvec3(1, 1, 2.5);
    o.raw.bigEndian = true;
    o.raw.headerBytes = 16;
    Volume w = loadVolume((dir / "data.raw").string(), o);
    CHECK(w.dims == glm::ivec3(3, 2, 1));
    CHECK(w.spacing.z == 2.5);
    CHECK(w.data == std::vector<float>{1, 2, 3, 4, 5, 6});
    CHECK_THAT(w.source, Catch::Contains("big-endian"));
}

TEST_CASE("slice folder: PNG slices in natural sort order", "[volume]") {
    auto dir = testTmpDir("volume_png");
    const int w = 5, h = 4, n = 12;
    for (int s = 1; s <= n; ++s) {
        std::vector<unsigned char> px(std::size_t(w * h));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                px[std::size_t(y * w + x)] = static_cast<unsigned char>(s * 10 + x);
        auto out = OIIO::ImageOutput::create("png");
        REQUIRE(out);
        std::string name = (dir / ("slice" + std::to_string(s) + ".png")).string();
        REQUIRE(out->open(name, OIIO::ImageSpec(w, h, 1, OIIO::TypeDesc::UINT8)));
        REQUIRE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
        out->close();
    }
    writeBytes(dir / "README.txt", "not a slice");
    Volume v = loadVolume(dir.string());
    REQUIRE(v.dims == glm::ivec3(w, h, n));
    for (int k = 0; k < n; ++k) CHECK(v.at(2, 1, k) == float((k + 1) * 10 + 2));
    CHECK_THAT(v.source, Catch::Contains("slice1.png .. slice12.png"));

    // A slice of another size is refused, naming the file.
    auto out = OIIO::ImageOutput::create("png");
    std::vector<unsigned char> px(6 * 4);
    out->open((dir / "slice13.png").string(), OIIO::ImageSpec(6, 4, 1, OIIO::TypeDesc::UINT8));
    out->write_image(OIIO::TypeDesc::UINT8, px.data());
    out->close();
    CHECK_THAT(errorOf([&] { loadVolume(dir.string()); }),
               Catch::Contains("slice13.png: slice is 6 x 4, the first slice is 5 x 4"));
}

namespace {

// Minimal uncompressed DICOM (explicit VR little endian) with 16-bit MONOCHROME2 pixels.
std::string dicomElement(std::uint16_t g, std::uint16_t e, const char* vr, std::string value) {
    if (value.size() % 2) value += std::string(vr) == "UI" ? '\0' : ' ';
    std::string s = bytesOf(g) + bytesOf(e) + vr;
    std::string v(vr);
    if (v == "OB" || v == "OW")
        s += bytesOf(std::uint16_t(0)) + bytesOf(std::uint32_t(value.size()));
    else
        s += bytesOf(std::uint16_t(value.size()));
    return s + value;
}

std::string dicomFile(int instance, int rows, int cols, std::uint16_t base) {
    std::string meta = dicomElement(2, 1, "OB", std::string("\0\1", 2)) +
                       dicomElement(2, 2, "UI", "1.2.840.10008.5.1.4.1.1.2") +
                       dicomElement(2, 3, "UI", "1.2.3." + std::to_string(instance)) +
                       dicomElement(2, 0x10, "UI", "1.2.840.10008.1.2.1");
    std::string ds = dicomElement(8, 0x16, "UI", "1.2.840.10008.5.1.4.1.1.2") +
                     dicomElement(8, 0x18, "UI", "1.2.3." + std::to_string(instance)) +
                     dicomElement(8, 0x60, "CS", "CT") +
                     dicomElement(0x20, 0x13, "IS", std::to_string(instance)) +
                     dicomElement(0x28, 2, "US", bytesOf(std::uint16_t(1))) +
                     dicomElement(0x28, 4, "CS", "MONOCHROME2") +
                     dicomElement(0x28, 0x10, "US", bytesOf(std::uint16_t(rows))) +
                     dicomElement(0x28, 0x11, "US", bytesOf(std::uint16_t(cols))) +
                     dicomElement(0x28, 0x100, "US", bytesOf(std::uint16_t(16))) +
                     dicomElement(0x28, 0x101, "US", bytesOf(std::uint16_t(16))) +
                     dicomElement(0x28, 0x102, "US", bytesOf(std::uint16_t(15))) +
                     dicomElement(0x28, 0x103, "US", bytesOf(std::uint16_t(0)));
    std::string px;
    for (int i = 0; i < rows * cols; ++i) px += bytesOf(std::uint16_t(base + i));
    ds += dicomElement(0x7fe0, 0x10, "OW", px);
    return std::string(128, '\0') + "DICM" +
           dicomElement(2, 0, "UL", bytesOf(std::uint32_t(meta.size()))) + meta + ds;
}

}  // namespace

TEST_CASE("DICOM folder: slices ordered by InstanceNumber", "[volume]") {
    auto dir = testTmpDir("volume_dicom");
    // File names in the opposite order of the instance numbers.
    writeBytes(dir / "a.dcm", dicomFile(3, 4, 3, 3000));
    writeBytes(dir / "b.dcm", dicomFile(2, 4, 3, 2000));
    writeBytes(dir / "c.dcm", dicomFile(1, 4, 3, 1000));
    Volume v;
    try {
        v = loadVolume(dir.string());
    } catch (const Error& e) {
        std::string msg = e.what();
        if (msg.find("DICOM not supported") != std::string::npos) {
            WARN("skipped: " << msg);
            return;
        }
        throw;
    }
    REQUIRE(v.dims == glm::ivec3(3, 4, 3));
    CHECK_THAT(v.note, Catch::Contains("InstanceNumber"));
    // Slices increase with instance number whatever the value scaling of the reader.
    CHECK(v.at(0, 0, 0) < v.at(0, 0, 1));
    CHECK(v.at(0, 0, 1) < v.at(0, 0, 2));
}
