// The free camera: eye, look-at point and up vector beside the orbit.
#include <catch2/catch.hpp>
#include <cmath>

#include "cli_util.h"
#include "splat/camera.h"
#include "splat/error.h"
#include "splat/render.h"
#include "splat/sequence.h"
#include "splat/synthetic.h"

using namespace splat;

namespace {
constexpr double kPi = 3.14159265358979323846;

double maxAbsDiff(const Image& a, const Image& b) {
    double w = 0;
    for (std::size_t n = 0; n < a.pixels.size(); ++n)
        for (int c = 0; c < 4; ++c) w = std::max(w, double(std::abs(a.pixels[n][c] - b.pixels[n][c])));
    return w;
}

// The orbit camera's eye for azimuth a, elevation e at distance d from the centre.
glm::dvec3 orbitEye(const Volume& v, double aDeg, double eDeg, double d) {
    const double a = aDeg * kPi / 180, e = eDeg * kPi / 180;
    const glm::dvec3 view(-std::sin(a) * std::cos(e), std::cos(a) * std::cos(e), -std::sin(e));
    return v.center() - view * d;
}
}  // namespace

TEST_CASE("free camera: eye/look-at/up reproduce the orbit camera", "[camera]") {
    const Volume v = makeSynthetic("phantom", 32);
    for (Projection proj : {Projection::Orthographic, Projection::Perspective}) {
        CameraParams orbit;
        orbit.width = orbit.height = 32;
        orbit.azimuthDeg = 35;
        orbit.elevationDeg = 20;
        orbit.projection = proj;
        orbit.distance = 80;
        CameraParams free = orbit;
        free.lookAtSet = true;
        free.eye = orbitEye(v, 35, 20, 80);
        free.lookAt = v.center();
        const Camera a(orbit, v), b(free, v);
        CHECK(glm::length(a.view - b.view) < 1e-12);
        CHECK(glm::length(a.right - b.right) < 1e-12);
        CHECK(glm::length(a.up - b.up) < 1e-12);
        CHECK(std::abs(a.pixelSize - b.pixelSize) < 1e-12 * a.pixelSize);
        RenderSettings s;
        s.camera = orbit;
        s.threads = 2;
        const Scene scene(v, s);
        for (RendererKind r : {RendererKind::Axis, RendererKind::Reference}) {
            INFO(toString(r) << (proj == Projection::Perspective ? " perspective" : " ortho"));
            CHECK(maxAbsDiff(scene.render(r, orbit), scene.render(r, free)) < 1e-5);
        }
    }
}

TEST_CASE("free camera: an off-centre look-at point shifts the orthographic image", "[camera]") {
    const Volume v = makeSynthetic("phantom", 32);
    CameraParams c;
    c.width = c.height = 48;
    c.lookAtSet = true;
    c.eye = orbitEye(v, 0, 0, 100);
    c.lookAt = v.center();
    const Camera centred(c, v);
    CameraParams shifted = c;
    const double px = centred.pixelSize;
    shifted.lookAt = v.center() + centred.right * (6 * px);  // 6 pixels to the right
    shifted.eye += centred.right * (6 * px);
    RenderSettings s;
    s.camera = c;
    s.threads = 2;
    const Scene scene(v, s);
    const Image a = scene.render(RendererKind::Axis, c), b = scene.render(RendererKind::Axis, shifted);
    // Pixel x of b shows what pixel x + 6 of a shows.
    double worst = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x + 6 < 48; ++x)
            worst = std::max(worst, double(glm::length(b.at(x, y) - a.at(x + 6, y))));
    CHECK(worst < 1e-5);
    CHECK(maxAbsDiff(a, b) > 1e-3);  // and it did move
}

TEST_CASE("free camera: bad vectors are refused in one line", "[camera]") {
    const Volume v = makeSynthetic("blob", 8);
    CameraParams c;
    c.lookAtSet = true;
    c.eye = c.lookAt = glm::dvec3(1.0);
    CHECK_THROWS_WITH(Camera(c, v), Catch::Contains("must differ"));
    c.eye = glm::dvec3(0, 0, 10);
    c.lookAt = glm::dvec3(0.0);
    CHECK_THROWS_WITH(Camera(c, v), Catch::Contains("parallel"));
    c.upHint = glm::dvec3(std::nan(""), 0, 1);
    CHECK_THROWS_WITH(Camera(c, v), Catch::Contains("finite"));
    c.upHint = glm::dvec3(0, 1, 0);
    CHECK_THROWS_WITH(CameraPath::turn(c, CameraPath::Angle::Azimuth, 0, 90, 4),
                      Catch::Contains("free camera"));

    using splat::test::runSplat;
    const auto ok = runSplat({"render", "synthetic:blob:16", "--size", "16x16", "--eye", "7.5,-40,7.5",
                              "-o", std::string(SPLAT_TEST_TMP) + "/free_eye.exr"});
    CHECK(ok.status == 0);
    const auto bad = runSplat({"render", "synthetic:blob:16", "--look-at", "1,2,3", "-o",
                               std::string(SPLAT_TEST_TMP) + "/free_bad.exr"});
    CHECK(bad.status == 2);
    CHECK(bad.err.find("--eye") != std::string::npos);
    const auto two = runSplat({"render", "synthetic:blob:16", "--eye", "1,2", "-o",
                               std::string(SPLAT_TEST_TMP) + "/free_bad2.exr"});
    CHECK(two.status == 2);
}
