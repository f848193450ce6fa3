// Slices, MPR and CPR through the reconstructed field; clipping.
#include <catch2/catch.hpp>
#include <cmath>

#include "cli_util.h"
#include "reference_util.h"
#include "splat/views.h"
#include "techniques_util.h"

using namespace splat;
using namespace splat::test;

TEST_CASE("mpr: an axis-aligned plane through voxel centres reproduces the reconstruction",
          "[techniques]") {
    const Volume v = makeSynthetic("phantom", 24);
    const FieldView field(v);
    const footprint::Kernel kernel = footprint::Kernel::defaultKernel();
    const PlaneView plane = slicePlane(v, 2, 11);
    REQUIRE(plane.width == 24);
    const Image im = multiplanarReconstruction(field, plane);
    double worst = 0;
    const int R = int(std::ceil(kernel.radius()));
    for (int j = 0; j < 24; j += 3)
        for (int i = 0; i < 24; i += 3) {
            // f at voxel (i, j, 11) summed directly from the kernel.
            double f = 0;
            for (int c = -R; c <= R; ++c)
                for (int b = -R; b <= R; ++b)
                    for (int a = -R; a <= R; ++a) {
                        const int x = i + a, y = j + b, z = 11 + c;
                        if (x < 0 || y < 0 || z < 0 || x >= 24 || y >= 24 || z >= 24) continue;
                        f += v.at(x, y, z) * kernel(std::sqrt(double(a * a + b * b + c * c)));
                    }
            // Pixel (i, 23 - j): +x right, +y up.
            worst = std::max(worst, std::abs(im.at(i, 23 - j).r - f));
        }
    INFO("worst |mpr - sum d h| " << worst);
    CHECK(worst < 1e-5);
}

TEST_CASE(
    "mpr: an oblique plane through a linear ramp reproduces the ramp within the kernel's "
    "ripple; cpr along a straight line equals the mpr of the same plane",
    "[techniques]") {
    Volume v = makeVolume(glm::ivec3(24), glm::dvec3(1.0), "ramp");
    for (int k = 0; k < 24; ++k)
        for (int j = 0; j < 24; ++j)
            for (int i = 0; i < 24; ++i)
                v.at(i, j, k) = float(1.0 + 0.05 * i + 0.03 * j + 0.02 * k);
    const FieldView field(v);
    PlaneView plane;
    plane.point = v.center();
    plane.normal = glm::normalize(glm::dvec3(1, 2, 3));
    plane.up = glm::dvec3(0, 0, 1);
    plane.width = plane.height = 20;
    plane.pixelSize = 0.4;
    const Image im = multiplanarReconstruction(field, plane);
    const glm::dvec3 n = glm::normalize(plane.normal);
    const glm::dvec3 right = glm::normalize(glm::cross(plane.up, n)), up = glm::cross(n, right);
    double worst = 0, bound = 0;
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) {
            const glm::dvec3 w =
                plane.point + (x + 0.5 - 10) * 0.4 * right + (10 - y - 0.5) * 0.4 * up;
            const double ramp = 1.0 + 0.05 * w.x + 0.03 * w.y + 0.02 * w.z;
            worst = std::max(worst, std::abs(im.at(x, y).r - ramp));
            bound = std::max(bound, field.partitionOfUnityRipple() * ramp + 1e-5);
        }
    INFO("worst |mpr - ramp| " << worst << ", ripple bound " << bound);
    CHECK(worst <= bound);
    // CPR along the straight line through the plane's centre column, lateral = image right:
    // rows run down the line (image -up), so it is the MPR above.
    const glm::dvec3 top = plane.point + 10 * 0.4 * up, bottom = plane.point - 10 * 0.4 * up;
    const Image cpr = curvedPlanarReformation(field, {top, plane.point, bottom}, right, 20, 0.4);
    REQUIRE(cpr.width == 20);
    REQUIRE(cpr.height == 20);
    double diff = 0;
    for (std::size_t p = 0; p < im.pixels.size(); ++p)
        diff = std::max(diff, double(std::abs(cpr.pixels[p].r - im.pixels[p].r)));
    CHECK(diff < 1e-5);
}

TEST_CASE(
    "clipping: a cut through a constant cube shows the constant's colour; a crop box "
    "around everything changes no pixel",
    "[techniques]") {
    const Volume v = onesVolume(24);
    const TransferFunction tf = greenTf();
    for (Classification c : {Classification::Pre, Classification::Post})
        for (RendererKind r : kAllRenderers) {
            INFO(toString(r) << " " << toString(c));
            RenderSettings s = techniqueSettings(r, RenderMode::Dvr, 48);
            s.classification = c;
            s.transfer = tf;
            const Image plain = render(v, s);
            s.clipping.cropBox = true;
            s.clipping.boxMin = glm::dvec3(-5.0);
            s.clipping.boxMax = glm::dvec3(30.0);
            CHECK(render(v, s).pixels == plain.pixels);
            // Cut away the half facing the camera (y < 11.5): the cut face is seen face on.
            s.clipping.cropBox = false;
            s.clipping.planes.push_back({v.center(), glm::dvec3(0, -1, 0)});
            const Image cut = render(v, s);
            const glm::vec4 centre = cut.at(24, 24);
            CHECK(centre.a > 0.99f);
            CHECK(centre.r / centre.a == Approx(0.2f).margin(0.01));
            CHECK(centre.g / centre.a == Approx(0.9f).margin(0.01));
            CHECK(centre.b / centre.a == Approx(0.3f).margin(0.01));
        }
}

TEST_CASE("slices, mpr and cpr commands write their images", "[techniques][cli]") {
    const auto dir = testTmpDir("tech_views");
    RunResult r = runSplat({"slices", "synthetic:phantom:16", "--axis", "z", "--every", "4", "-o",
                            (dir / "s").string(), "--scale-bar", "5"});
    INFO(r.err);
    CHECK(r.status == 0);
    CHECK(std::filesystem::exists(dir / "s" / "mosaic.png"));
    CHECK(std::filesystem::exists(dir / "s" / "slice_z0004.png"));
    r = runSplat({"mpr", "synthetic:phantom:16", "--plane", "7.5,7.5,7.5,1,1,1", "--size", "24x24",
                  "--pixel-size", "0.7", "-o", (dir / "m.png").string(), "--bit-depth", "16"});
    CHECK(r.status == 0);
    std::ofstream((dir / "c.json").string())
        << R"({"points": [[2, 7.5, 7.5], [7.5, 7.5, 4], [13, 7.5, 7.5]], "width": 20})";
    r = runSplat({"cpr", "synthetic:phantom:16", "--curve", (dir / "c.json").string(), "-o",
                  (dir / "c.png").string()});
    CHECK(r.status == 0);
    CHECK(std::filesystem::exists(dir / "c.png"));
}
