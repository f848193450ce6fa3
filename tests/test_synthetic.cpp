// Synthetic volumes: deterministic, right sizes, the phantom's densities where Kak &
// Slaney put them, the sphere's volume.
#include <catch2/catch.hpp>
#include <cmath>

#include "splat/synthetic.h"
#include "splat/volume_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;

TEST_CASE("synthetic volumes are deterministic and sized N^3", "[volume]") {
    for (const std::string& name : syntheticNames()) {
        Volume a = makeSynthetic(name, 24), b = makeSynthetic(name, 24);
        CHECK(a.dims == glm::ivec3(24));
        CHECK(a.spacing == glm::dvec3(1.0));
        CHECK(a.origin == glm::dvec3(0.0));
        CHECK(a.data == b.data);
        VolumeStats s = volumeStats(a);
        CHECK(s.maxValue > s.minValue);
    }
    CHECK(syntheticDefaultSize("phantom") == 128);
    CHECK(syntheticDefaultSize("blob") == 64);
    CHECK(loadVolume("synthetic:cube").dims == glm::ivec3(64));
    CHECK(loadVolume("synthetic:blob:17").dims == glm::ivec3(17));
    CHECK_THAT(errorOf([] { makeSynthetic("teapot", 16); }),
               Catch::Contains("unknown synthetic volume (available: phantom, ct-phantom, blob"));
    CHECK_THAT(errorOf([] { makeSynthetic("cube", 0); }), Catch::Contains("between 1 and 2048"));
    CHECK_THAT(errorOf([] { loadVolume("synthetic:cube:abc"); }),
               Catch::Contains("size must be an integer"));
    CHECK_THAT(errorOf([] { loadVolume("synthetic:cube:4096"); }),
               Catch::Contains("between 1 and 2048"));
}

TEST_CASE("phantom: brain ~1.0 at the centre, skull 2.0, head upright", "[volume]") {
    const int n = 128;
    Volume v = makeSynthetic("phantom", n);
    CHECK(v.at(64, 64, 64) == Approx(1.02));
    CHECK(v.at(63, 63, 63) == Approx(1.02));
    // Top of the skull along +z (phantom long axis 0.92 -> z): between 0.874 and 0.92.
    CHECK(v.at(64, 64, 121) == Approx(2.0));
    // Sides along x (semi-axes 0.6624..0.69): skull too, at |x| = 0.675.
    CHECK(v.at(int(63.5 + 0.675 * 64), 64, 64) == Approx(2.0));
    // Outside the head.
    CHECK(v.at(64, 64, 126) == 0.0f);
    CHECK(v.at(0, 0, 0) == 0.0f);
    // Long axis is z: the head extends further along z than along x.
    auto extent = [&](int axis) {
        int count = 0;
        for (int t = 0; t < n; ++t) {
            glm::ivec3 p(64);
            p[axis] = t;
            count += v.at(p.x, p.y, p.z) > 0 ? 1 : 0;
        }
        return count;
    };
    CHECK(extent(2) > extent(0));
    VolumeStats s = volumeStats(v);
    CHECK(s.minValue == Approx(0.0));
    CHECK(s.maxValue == Approx(2.0));
}

TEST_CASE("sphere voxel sum is the smooth ball's volume 4/3 pi (r^3 + 3 r w^2 / 7)", "[volume]") {
    // The antialiased ball: the edge profile's second moment is w^2 / 7.
    for (int n : {32, 64}) {
        Volume v = makeSynthetic("sphere", n);
        double count = 0;
        for (float d : v.data) count += d;
        const double r = syntheticSphereRadius(n), w = syntheticSphereEdge();
        CHECK(count ==
              Approx(4.0 / 3.0 * M_PI * (r * r * r + 3.0 * r * w * w / 7.0)).epsilon(1e-3));
        CHECK(v.at(0, 0, 0) == 0.0f);
        CHECK(v.at(n / 2, n / 2, n / 2) == 1.0f);
    }
    Volume cube = makeSynthetic("cube", 32);
    double c = 0;
    for (float d : cube.data) c += d;
    CHECK(c == 16.0 * 16 * 16);
    Volume blob = makeSynthetic("blob", 33);
    CHECK(blob.at(16, 16, 16) == Approx(1.0));
    CHECK(blob.at(16, 16, 16 + 4) == Approx(std::exp(-16.0 / (2 * 33.0 * 33.0 / 64))));
    Volume ml = makeSynthetic("marschner-lobb", 41);
    VolumeStats s = volumeStats(ml);
    CHECK(s.minValue >= 0.0f);
    CHECK(s.maxValue <= 1.0f);
}
