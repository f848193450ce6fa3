// The image-aligned splatter's step "cut" (splatters/image_aligned.cpp): kernels whose
// rectangles are at most 4 pixels wide take two rows per vector; the sheets must receive the
// same sums as with one row per vector, bit for bit.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "footprint/footprint_poly.h"
#include "footprint/lanes.h"
#include "footprint/slab_table.h"
#include "splatters/splatter.h"

using namespace splat;

#if defined(FOOTPRINT_HAVE_LANES)
TEST_CASE("slab sections: two rows per vector fill the sheets of one row per vector, bit for bit",
          "[slab][stages]") {
    if (!footprint::cpuHasLanes()) {
        WARN("this CPU has no AVX2 + FMA: the scalar sections are used everywhere");
        return;
    }
    const footprint::Kernel kernel = footprint::Kernel::fromName("gaussian", 0, 0);
    const footprint::SlabTable table(kernel);
    REQUIRE(table.closedForm());
    const footprint::FootprintPoly poly(table.footprint());
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(-1.0, 1.0), pixel(0.25, 1.5), slab(0.3, 1.5);
    std::uniform_real_distribution<float> pos(-3.0f, 35.0f), val(0.0f, 2.0f), phase(0.0f, 1.0f);
    // A tile at (32, 64) of a 96 x 128 image; orthographic views of isotropic voxels (the
    // slab boundaries do not depend on the pixel), pixels of 0.25 to 1.5 voxels: boxes 3 to
    // 17 pixels wide, cut by the tile's edges.
    const int ox = 32, oy = 64, width = 96, height = 128;
    int narrow = 0, wide = 0;
    for (int view = 0; view < 16; ++view) {
        const glm::dvec3 dir = glm::normalize(glm::dvec3(u(rng), u(rng), 1.5 + u(rng)));
        const glm::dvec3 right = glm::normalize(glm::cross(dir, glm::dvec3(0.3, 1.0, 0.1)));
        const glm::dvec3 up = glm::cross(right, dir);
        const double size = pixel(rng);
        const footprint::EllipticalFootprint e = footprint::ellipticalFootprint(
            glm::dvec3(1.0), right * size, -up * size, dir, kernel.radius());
        // The rays' closest approach to the centre is at its depth: the two-row path applies.
        REQUIRE(e.depthScale * (std::abs(e.tx) * e.halfWidth + std::abs(e.ty) * e.halfHeight) <=
                1e-6f);
        const float thickness = float(slab(rng));
        const int n = int(std::ceil(2.0 * kernel.radius() / thickness)) + 1;
        std::vector<std::unique_ptr<SheetBuffer<4>>> paired, single;
        std::vector<SheetBuffer<4>*> p, s;
        for (int j = 0; j < n; ++j) {
            paired.push_back(std::make_unique<SheetBuffer<4>>(ox, oy, 32, 32));
            single.push_back(std::make_unique<SheetBuffer<4>>(ox, oy, 32, 32));
            p.push_back(paired.back().get());
            s.push_back(single.back().get());
        }
        const bool ascending = view % 2 == 0;  // front to back, or back to front
        for (int k = 0; k < 60; ++k) {
            const float sx = float(ox) + pos(rng), sy = float(oy) + pos(rng);
            const PixelRect r = clipToTile(footprintRect(sx, sy, e, width, height),
                                           TileGrid(width, height, 32), ox, oy);
            if (r.empty()) continue;
            (r.x1 - r.x0 < 4 ? narrow : wide) += 1;
            // n slabs around the centre at a random phase, in visiting order.
            std::vector<float> tb(std::size_t(n) + 1);
            const float first = -float(kernel.radius()) - phase(rng) * thickness;
            for (int b = 0; b <= n; ++b)
                tb[std::size_t(b)] =
                    ascending ? first + float(b) * thickness : first + float(n - b) * thickness;
            const float v[4] = {val(rng), val(rng), val(rng), val(rng)};
            const int a = cutIntoSlabs(p.data(), n, v, sx, sy, e, r, table, &poly, tb.data(), true);
            const int b =
                cutIntoSlabs(s.data(), n, v, sx, sy, e, r, table, &poly, tb.data(), false);
            REQUIRE(a == b);
        }
        for (int j = 0; j < n; ++j)
            for (int c = 0; c < 4; ++c)
                for (int y = 0; y < 32; ++y)
                    REQUIRE(std::memcmp(p[j]->row(c, y), s[j]->row(c, y), 32 * sizeof(float)) == 0);
    }
    INFO(narrow << " narrow and " << wide << " wide boxes");
    CHECK(narrow > 100);
    CHECK(wide > 100);
}
#endif
