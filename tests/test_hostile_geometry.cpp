// Absurd geometry and parameters: spacings 1e-30,1,1 and 1e-6,1,1e6 and a NaN
// or Inf origin crashed the image-aligned splatter (unchecked float -> uint32 slab index);
// a reference step of 1e-9 voxels silently became the coarsest step. Each now stops with
// one splat::Error before any frame work, for every renderer.
#include <catch2/catch.hpp>
#include <limits>

#include "splat/error.h"
#include "splat/render.h"
#include "splat/scene.h"
#include "splat/transfer.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;

namespace {

Volume blob(glm::dvec3 spacing, glm::dvec3 origin = glm::dvec3(0.0)) {
    Volume v = makeVolume(glm::ivec3(6), spacing, "blob");
    v.origin = origin;
    for (int k = 2; k < 4; ++k)
        for (int j = 2; j < 4; ++j)
            for (int i = 2; i < 4; ++i) v.at(i, j, k) = 1.0f;
    return v;
}

std::string sceneError(const Volume& v, RendererKind r, double elevation = 0) {
    RenderSettings s;
    s.renderer = r;
    s.mode = RenderMode::Dvr;
    s.camera.width = s.camera.height = 16;
    s.camera.elevationDeg = elevation;
    s.threads = 1;
    return errorOf([&] {
        Scene scene(v, s);
        scene.render(s);
    });
}

}  // namespace

TEST_CASE("absurd spacings and non-finite origins are refused by every renderer",
          "[hostile][render]") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet, RendererKind::Reference}) {
        INFO("renderer " << int(r));
        CHECK_THAT(sceneError(blob({1e-30, 1, 1}), r), Catch::Contains("exceeds 10000:1"));
        CHECK_THAT(sceneError(blob({1e-6, 1, 1e6}), r, 90.0), Catch::Contains("exceeds 10000:1"));
        CHECK_THAT(sceneError(blob({1, 1, 1}, {nan, 0, 0}), r),
                   Catch::Contains("origin is NaN or Inf"));
        CHECK_THAT(sceneError(blob({1, 1, 1}, {0, 0, inf}), r),
                   Catch::Contains("origin is NaN or Inf"));
        CHECK_THAT(sceneError(blob({1, 1, 1}, {0, 3e9, 0}), r),
                   Catch::Contains("exceed 1e9 world units"));
        // The limits are limits, not a change of what renders: 1:1000 still works.
        CHECK(sceneError(blob({1, 1, 1000}), r).empty());
    }
}

TEST_CASE("a reference step of 1e-9 voxels is refused, not coarsened", "[hostile][render]") {
    Volume v = blob({1, 1, 1});
    RenderSettings s;
    s.renderer = RendererKind::Reference;
    s.camera.width = s.camera.height = 8;
    s.threads = 1;
    Scene scene(v, s);
    RenderSettings tiny = s;
    tiny.quality.referenceStep = 1e-9;
    CHECK_THAT(errorOf([&] { scene.render(tiny); }),
               Catch::Contains("referenceStep must be finite and >= 0.001 voxels"));
    for (double step : {-1.0, std::numeric_limits<double>::quiet_NaN()}) {
        RenderSettings f = s;
        f.quality.referenceStep = step;
        CHECK_THAT(errorOf([&] { scene.render(f); }), Catch::Contains("reference step"));
    }
    RenderSettings automatic = s;  // 0: the automatic first step (referenceStepFor)
    automatic.quality.referenceStep = 0.0;
    CHECK_NOTHROW(scene.render(automatic));
    RenderSettings ok = s;
    ok.quality.referenceStep = 1e-3;
    ok.quality.referenceTolerance = 1e9;
    CHECK_NOTHROW(scene.render(ok));
}

TEST_CASE("render refuses absurd spacings with one line and nothing written",
          "[hostile][render][cli]") {
    auto dir = testTmpDir("hostile_geometry_cli");
    const std::string raw = (dir / "v_6x6x6_uint8.raw").string();
    writeBytes(raw, std::string(216, '\x40'));
    const std::string out = (dir / "out.png").string();
    for (const auto& extra : std::vector<std::vector<std::string>>{
             {"--spacing", "1e-30,1,1", "--renderer", "sheet"},
             {"--spacing", "1e-6,1,1e6", "--elevation", "90", "--renderer", "sheet"},
             {"--spacing", "1e-30,1,1", "--renderer", "axis"}}) {
        std::vector<std::string> args{"render", raw, "--size", "16x16", "-o", out};
        args.insert(args.end(), extra.begin(), extra.end());
        RunResult r = runSplat(args);
        INFO(r.err);
        CHECK(r.status == 1);
        REQUIRE(r.errLines().size() >= 1);
        CHECK_THAT(r.errLines().back(),
                   Catch::StartsWith("splat: error: ") && Catch::Contains("exceeds 10000:1"));
        CHECK_FALSE(std::filesystem::exists(out));
    }
}
