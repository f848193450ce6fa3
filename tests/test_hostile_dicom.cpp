// DICOM series read right: order along the slice normal whatever the
// InstanceNumbers and file names, spacing from PixelSpacing and the positions, values in
// Hounsfield units, one series per volume, upright like NIfTI. The series are written here
// with GDCM's writer.
#include <catch2/catch.hpp>

#include "dicom_util.h"
#include "splat/volume_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

const char* kUidA = "1.2.826.0.1.3680043.2.1125.77.1";
const char* kUidB = "1.2.826.0.1.3680043.2.1125.77.2";

// Hounsfield value of series A at column c, row r of the k-th slice from the feet.
double huA(int c, int r, int k) { return 100.0 * k + 10.0 * r + c - 500.0; }

// Series A: 4 x 3 pixels of 0.5 x 0.5 mm, 5 slices 2.5 mm apart going up (LPS z), stored
// values HU + 1024 with a rescale intercept of -1024. `names[k]` is the file of slice k,
// `instances[k]` its InstanceNumber.
void writeSeriesA(const fs::path& dir, const std::vector<std::string>& names,
                  const std::vector<int>& instances, const std::vector<double>& z = {}) {
    for (int k = 0; k < 5; ++k) {
        DicomSlice s;
        s.columns = 4;
        s.rows = 3;
        s.position = {-10.0, -20.0, z.empty() ? 30.0 + 2.5 * k : z[std::size_t(k)]};
        s.intercept = -1024;
        s.instance = instances[std::size_t(k)];
        s.seriesUid = kUidA;
        s.seriesNumber = 3;
        s.description = "head CT";
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) s.stored.push_back(std::int16_t(huA(c, r, k) + 1024));
        writeDicomSlice(dir / names[std::size_t(k)], s);
    }
}

// Series B in the same folder: 2 x 2 pixels, 3 slices.
void writeSeriesB(const fs::path& dir) {
    for (int k = 0; k < 3; ++k) {
        DicomSlice s;
        s.columns = s.rows = 2;
        s.position = {0, 0, 5.0 * k};
        s.instance = k + 1;
        s.seriesUid = kUidB;
        s.seriesNumber = 4;
        s.description = "scout";
        s.stored = {1, 2, 3, 4};
        writeDicomSlice(dir / ("b" + std::to_string(k)).append(".dcm"), s);
    }
}

void checkSeriesA(const Volume& v) {
    REQUIRE(v.dims == glm::ivec3(4, 3, 5));
    CHECK(v.spacing.x == Approx(0.5));
    CHECK(v.spacing.y == Approx(0.5));
    CHECK(v.spacing.z == Approx(2.5));
    // LPS -> RAS (the NIfTI world): x and y are negated, so the columns and rows run
    // backwards; z (superior) keeps its direction: the head is upright.
    CHECK(v.origin.x == Approx(10.0 - 0.5 * 3));
    CHECK(v.origin.y == Approx(20.0 - 0.5 * 2));
    CHECK(v.origin.z == Approx(30.0));
    for (int k = 0; k < 5; ++k)
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 4; ++i) REQUIRE(v.at(i, j, k) == float(huA(3 - i, 2 - j, k)));
    CHECK(v.note.find("oblique") == std::string::npos);
}

}  // namespace

TEST_CASE("DICOM: shuffled InstanceNumbers, two series, Hounsfield units, upright",
          "[volume][dicom][hostile]") {
    LoadOptions a;
    a.dicomSeries = kUidA;
    SECTION("file names in position order, InstanceNumbers shuffled") {
        auto dir = testTmpDir("dicom_order1");
        writeSeriesA(dir, {"s1.dcm", "s2.dcm", "s3.dcm", "s4.dcm", "s5.dcm"}, {3, 5, 1, 4, 2});
        writeSeriesB(dir);
        checkSeriesA(loadVolume(dir.string(), a));
    }
    SECTION("file names and InstanceNumbers against the positions") {
        auto dir = testTmpDir("dicom_order2");
        writeSeriesA(dir, {"s5.dcm", "s4.dcm", "s3.dcm", "s2.dcm", "s1.dcm"}, {5, 4, 3, 2, 1});
        writeSeriesB(dir);
        checkSeriesA(loadVolume(dir.string(), a));
    }
    SECTION("two series without --series: refused, both listed") {
        auto dir = testTmpDir("dicom_two");
        writeSeriesA(dir, {"s1.dcm", "s2.dcm", "s3.dcm", "s4.dcm", "s5.dcm"}, {1, 2, 3, 4, 5});
        writeSeriesB(dir);
        std::string msg = errorOf([&] { loadVolume(dir.string()); });
        CHECK_THAT(msg, Catch::Contains("holds 2 DICOM series") && Catch::Contains(kUidA) &&
                            Catch::Contains(kUidB) && Catch::Contains("--series"));
        auto list = listDicomSeries(dir.string());
        REQUIRE(list.size() == 2);
        CHECK(list[0].uid == kUidA);
        CHECK(list[0].files == 5);
        CHECK(list[0].columns == 4);
        CHECK(list[0].rows == 3);
        CHECK(list[0].description == "head CT");
        CHECK(list[1].uid == kUidB);
        CHECK(list[1].files == 3);
        LoadOptions b;
        b.dicomSeries = kUidB;
        Volume vb = loadVolume(dir.string(), b);
        CHECK(vb.dims == glm::ivec3(2, 2, 3));
        CHECK(vb.spacing.z == Approx(5.0));
        b.dicomSeries = "1.2.3.4";
        CHECK_THAT(errorOf([&] { loadVolume(dir.string(), b); }),
                   Catch::Contains("no DICOM series with SeriesInstanceUID 1.2.3.4"));
        // `splat info FOLDER` lists the series; --series loads one.
        RunResult r = runSplat({"info", dir.string()});
        CHECK(r.status == 0);
        CHECK_THAT(r.out, Catch::Contains("2 DICOM series") && Catch::Contains(kUidA) &&
                              Catch::Contains("head CT") && Catch::Contains("5 files of 4 x 3"));
        r = runSplat({"info", dir.string(), "--series", kUidA});
        CHECK(r.status == 0);
        CHECK_THAT(r.out, Catch::Contains("4 x 3 x 5"));
    }
    SECTION("uneven gaps are refused, duplicates too") {
        auto dir = testTmpDir("dicom_gaps");
        writeSeriesA(dir, {"s1.dcm", "s2.dcm", "s3.dcm", "s4.dcm", "s5.dcm"}, {1, 2, 3, 4, 5},
                     {0, 2.5, 5, 10, 12.5});
        CHECK_THAT(errorOf([&] { loadVolume(dir.string()); }),
                   Catch::Contains("uneven DICOM slice gaps") && Catch::Contains("from 2.5 to 5"));
        auto dup = testTmpDir("dicom_dup");
        writeSeriesA(dup, {"s1.dcm", "s2.dcm", "s3.dcm", "s4.dcm", "s5.dcm"}, {1, 2, 3, 4, 5},
                     {0, 2.5, 2.5, 5, 7.5});
        CHECK_THAT(errorOf([&] { loadVolume(dup.string()); }),
                   Catch::Contains("lie at the same position"));
    }
    SECTION("a gantry tilt is a warning") {
        auto dir = testTmpDir("dicom_tilt");
        for (int k = 0; k < 4; ++k) {
            DicomSlice s;
            s.position = {0.0, 0.5 * k, 2.5 * k};  // each slice shifted 0.5 mm posterior
            s.instance = k + 1;
            s.stored.assign(12, std::int16_t(k));
            writeDicomSlice(dir / ("t" + std::to_string(k) + ".dcm"), s);
        }
        Volume v = loadVolume(dir.string());
        CHECK(v.dims == glm::ivec3(4, 3, 4));
        CHECK(v.spacing.z == Approx(2.5));
        // atan(0.5 / 2.5) = 11.31 degrees
        CHECK_THAT(v.note, Catch::Contains("gantry tilt of 11.31 degrees"));
    }
}

TEST_CASE("DICOM element lengths are checked before GDCM allocates", "[volume][dicom][hostile]") {
    auto dir = testTmpDir("dicom_lengths");
    DicomSlice s;
    s.stored.assign(12, 7);
    writeDicomSlice(dir / "ok.dcm", s);
    std::string bytes = readTextFile(dir / "ok.dcm");
    CHECK(loadVolume((dir / "ok.dcm").string()).data[0] == 7.0f);
    // The pixel data element (7fe0,0010) declares 4.2 GB (found by fuzz_dicom: GDCM
    // allocated it before reading). GDCM writes implicit VR little endian: tag, 4-byte length.
    const std::size_t at = bytes.rfind(std::string("\xe0\x7f\x10\x00", 4));
    REQUIRE(at != std::string::npos);
    const std::uint32_t huge = 4211081216u;
    std::memcpy(&bytes[at + 4], &huge, 4);
    writeBytes(dir / "huge.dcm", bytes);
    CHECK_THAT(errorOf([&] { loadVolume((dir / "huge.dcm").string()); }),
               Catch::Contains("huge.dcm: malformed DICOM file (element (7fe0,0010) declares "
                               "4211081216 bytes, the file holds 24)"));
    // A file that ends right after its meta group made Debian's GDCM abort on an assert
    // (found by fuzz_dicom); so would a sequence in the meta group.
    const std::size_t dataSet = bytes.find(std::string("\x08\x00", 2), 132);
    REQUIRE(dataSet != std::string::npos);
    writeBytes(dir / "metaonly.dcm", bytes.substr(0, dataSet));
    CHECK_THAT(errorOf([&] { loadVolume((dir / "metaonly.dcm").string()); }),
               Catch::Contains("no data set after the file meta information"));
    // An unknown PhotometricInterpretation made gdcm::ImageReader abort on an assert (found
    // by fuzz_dicom); the pixels are now decoded without it, so this loads.
    std::string odd = readTextFile(dir / "ok.dcm");
    const std::size_t pi = odd.find("MONOCHROME2");
    REQUIRE(pi != std::string::npos);
    odd.replace(pi, 11, "XONOCHROMEX");
    writeBytes(dir / "odd.dcm", odd);
    CHECK(loadVolume((dir / "odd.dcm").string()).data[11] == 7.0f);
    // Not a Part 10 file: refused, not guessed at.
    writeBytes(dir / "nopreamble.dcm", bytes.substr(132));
    CHECK_THAT(errorOf([&] { loadVolume((dir / "nopreamble.dcm").string()); }),
               Catch::Contains("no DICM marker"));
}

namespace {
std::string le16(unsigned v) { return {char(v & 0xFF), char(v >> 8 & 0xFF)}; }
std::string le32(std::uint32_t v) { return le16(v & 0xFFFF) + le16(v >> 16); }
std::string tagOf(unsigned g, unsigned e, std::uint32_t len) { return le16(g) + le16(e) + le32(len); }
}  // namespace

TEST_CASE("DICOM: GDCM dying on a file is one error line, never the process",
          "[volume][dicom][hostile]") {
    auto dir = testTmpDir("dicom_gdcm_abort");
    DicomSlice s;
    s.stored.assign(12, 7);
    writeDicomSlice(dir / "ok.dcm", s);
    const std::string bytes = readTextFile(dir / "ok.dcm");
    const std::size_t dataSet = bytes.find(std::string("\x08\x00", 2), 132);
    REQUIRE(dataSet != std::string::npos);
    // An implicit-VR sequence (0008,1140) of undefined length whose item of undefined length
    // never ends (no item delimiter): Debian's GDCM aborts in gdcm::DataSet::ReadNested
    // (SIGABRT). Every length is within the file, so the element walk lets it through. The
    // file ends with Pixel Data (a file without any is refused before GDCM reads it).
    const std::string nested = tagOf(0x0008, 0x1140, 0xFFFFFFFFu) +
                               tagOf(0xFFFE, 0xE000, 0xFFFFFFFFu) + tagOf(0x0010, 0x0010, 4) +
                               "ABCD" + tagOf(0xFFFE, 0xE0DD, 0) + tagOf(0x0010, 0x0020, 4) +
                               "EFGH" + tagOf(0x7FE0, 0x0010, 24) + std::string(24, '\7');
    writeBytes(dir / "nested.dcm", bytes.substr(0, dataSet) + nested);
    CHECK_THAT(errorOf([&] { loadVolume((dir / "nested.dcm").string()); }),
               Catch::EndsWith("nested.dcm: malformed DICOM file (GDCM reading the header died "
                               "on it with SIGABRT, a failed assertion)"));
    // In a series, the error names the file GDCM died on, and the good slices do not hide it.
    auto series = testTmpDir("dicom_gdcm_abort_series");
    fs::copy_file(dir / "ok.dcm", series / "a.dcm");
    fs::copy_file(dir / "nested.dcm", series / "b.dcm");
    CHECK_THAT(errorOf([&] { loadVolume(series.string()); }),
               Catch::Contains("b.dcm: malformed DICOM file (GDCM reading the header died"));
    // A group-fffe tag that is no item or delimiter (found by fuzz_dicom seeded with
    // pydicom's files: GDCM read (fffe,650d) as an element and allocated its 3.7 GB).
    writeBytes(dir / "itemtag.dcm", bytes.substr(0, dataSet) +
                                        tagOf(0xFFFE, 0x650D, 0xE0000000u) + "ABCD");
    CHECK_THAT(errorOf([&] { loadVolume((dir / "itemtag.dcm").string()); }),
               Catch::EndsWith("itemtag.dcm: malformed DICOM file (invalid item tag (fffe,650d))"));
    // An element that runs past the end of its item of defined length: GDCM resumes at
    // the item's declared end, the walk would not (found by fuzz_dicom: GDCM then read a
    // 540 MB length the walk never saw).
    writeBytes(dir / "crossing.dcm",
               bytes.substr(0, dataSet) + tagOf(0x0008, 0x1140, 20) +
                   tagOf(0xFFFE, 0xE000, 10) + tagOf(0x0008, 0x1150, 4) + "ABCD" +
                   tagOf(0x0010, 0x0010, 0) + bytes.substr(dataSet));
    CHECK_THAT(errorOf([&] { loadVolume((dir / "crossing.dcm").string()); }),
               Catch::EndsWith("crossing.dcm: malformed DICOM file (an element crosses the end "
                               "of its item or sequence)"));
    // The process is still here and reads the good file.
    CHECK(loadVolume((dir / "ok.dcm").string()).data[0] == 7.0f);
}
