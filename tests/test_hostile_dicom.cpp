// DICOM series read right (issue 14): order along the slice normal whatever the
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
        writeDicomSlice(dir / ("b" + std::to_string(k) + ".dcm"), s);
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
