// Volume basics: makeVolume validation, statistics, description, writer round trips.
#include <catch2/catch.hpp>

#include "splat/volume_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;

namespace {

Volume testVolume() {
    Volume v = makeVolume({5, 4, 3}, {0.5, 1.25, 2.0}, "test");
    for (std::size_t i = 0; i < v.data.size(); ++i) v.data[i] = float(i) * 0.5f - 7.0f;
    v.origin = {-10.0, 3.5, 20.0};
    return v;
}

void requireSame(const Volume& a, const Volume& b) {
    REQUIRE(a.dims == b.dims);
    REQUIRE(a.data == b.data);
    for (int k = 0; k < 3; ++k) {
        CHECK(a.spacing[k] == Approx(b.spacing[k]).epsilon(1e-6));
        CHECK(a.origin[k] == Approx(b.origin[k]).epsilon(1e-6));
    }
}

}  // namespace

TEST_CASE("makeVolume validates dimensions and spacing", "[volume]") {
    Volume v = makeVolume({2, 3, 4}, {1, 2, 3}, "x");
    CHECK(v.voxelCount() == 24);
    CHECK(v.data.size() == 24);
    CHECK(v.data[23] == 0.0f);
    CHECK(v.index(1, 2, 3) == 23);

    CHECK_THAT(errorOf([] {
                   makeVolume({0, 3, 4}, {1, 1, 1}, "vol.raw");
               }),
               Catch::StartsWith("vol.raw: invalid dimensions 0 x 3 x 4"));
    CHECK_THAT(errorOf([] {
                   makeVolume({2, -3, 4}, {1, 1, 1}, "v");
               }),
               Catch::Contains("y must be at least 1"));
    // More than 2^32 voxels is refused, and the product is computed without overflow.
    CHECK_THAT(errorOf([] {
                   makeVolume({65536, 65536, 65536}, {1, 1, 1}, "big");
               }),
               Catch::Contains("too large"));
    CHECK_THAT(errorOf([] {
                   makeVolume({2147483647, 2147483647, 2147483647}, {1, 1, 1}, "big");
               }),
               Catch::Contains("too large"));
    CHECK_THAT(errorOf([] {
                   makeVolume({2, 2, 2}, {1, 0, 1}, "s");
               }),
               Catch::Contains("invalid spacing"));
    CHECK_THAT(errorOf([] {
                   makeVolume({2, 2, 2}, {1, 1, -2}, "s");
               }),
               Catch::Contains("invalid spacing"));
    CHECK_THAT(errorOf([] {
                   makeVolume({2, 2, 2}, {std::nan(""), 1, 1}, "s");
               }),
               Catch::Contains("invalid spacing"));
}

TEST_CASE("volumeStats and describeVolume", "[volume]") {
    Volume v = makeVolume({4, 2, 1}, {1, 1, 1}, "stats");
    v.data = {0, 1, 2, 3, 4, 5, 6, 7};
    VolumeStats s = volumeStats(v, 4);
    CHECK(s.minValue == 0.0f);
    CHECK(s.maxValue == 7.0f);
    CHECK(s.mean == Approx(3.5));
    REQUIRE(s.histogram.size() == 4);
    CHECK(s.histogram == std::vector<std::size_t>{2, 2, 2, 2});

    v.note = "something to know";
    v.source = "unit test";
    std::string d = describeVolume(v);
    CHECK_THAT(d, Catch::Contains("4 x 2 x 1"));
    CHECK_THAT(d, Catch::Contains("1 x 1 x 1 mm"));
    CHECK_THAT(d, Catch::Contains("unit test"));
    CHECK_THAT(d, Catch::Contains("0 .. 7, mean 3.5"));
    CHECK_THAT(d, Catch::Contains("histogram"));
    CHECK_THAT(d, Catch::Contains("#"));
    CHECK_THAT(d, Catch::Contains("MiB"));
    CHECK_THAT(d, Catch::Contains("something to know"));

    Volume c = makeVolume({2, 2, 2}, {1, 1, 1}, "constant");  // all zero: one full bin
    VolumeStats cs = volumeStats(c, 8);
    CHECK(cs.histogram[0] == 8);
}

TEST_CASE("writers round-trip through the loaders", "[volume]") {
    auto dir = testTmpDir("volume_roundtrip");
    Volume v = testVolume();
    for (const char* name : {"a.nii", "a.nii.gz", "a.nrrd", "a.mha", "a.mhd"}) {
        DYNAMIC_SECTION(name) {
            std::string path = (dir / name).string();
            std::string ext = std::string(name).substr(1);
            if (ext.rfind(".nii", 0) == 0)
                saveNifti(path, v);
            else if (ext == ".nrrd")
                saveNrrd(path, v);
            else
                saveMetaImage(path, v);
            Volume w = loadVolume(path);
            requireSame(v, w);
            CHECK(w.note.empty());
        }
    }
    // No temporaries left behind.
    for (const auto& e : std::filesystem::directory_iterator(dir))
        CHECK(e.path().filename().string().find(".tmp") == std::string::npos);
}

TEST_CASE("writers refuse bad targets and leave nothing behind", "[volume]") {
    auto dir = testTmpDir("volume_write_fail");
    Volume v = testVolume();
    CHECK_THROWS_AS(saveNrrd((dir / "missing" / "x.nrrd").string(), v), Error);
    CHECK_THROWS_AS(saveMetaImage((dir / "x.vtk").string(), v), Error);
    CHECK_THROWS_AS(saveNifti((dir / "x.img").string(), v), Error);
    CHECK(std::filesystem::is_empty(dir));
}

TEST_CASE("ch2.nii.gz loads as 181x217x181 at 1 mm", "[volume]") {
    const std::string ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
    if (!std::filesystem::exists(ch2)) {
        WARN("skipped: " << ch2 << " is not installed");
        return;
    }
    Volume v = loadVolume(ch2);
    CHECK(v.dims == glm::ivec3(181, 217, 181));
    CHECK(v.spacing.x == Approx(1.0));
    CHECK(v.spacing.y == Approx(1.0));
    CHECK(v.spacing.z == Approx(1.0));
    CHECK_THAT(v.source, Catch::Contains("NIfTI-1"));
    CHECK(v.note.empty());
    VolumeStats s = volumeStats(v);
    CHECK(s.maxValue > s.minValue);
}
