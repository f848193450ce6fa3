// Popping of Gaussian scenes, through the popping analyzer's frame callback
// (PoppingOptions::renderFrame): the analyzer's three renderer slots carry the Gaussian
// renderers (axis -> 3dgs, sheet -> sheet, reference -> reference). The scene built to pop,
// two overlapping Gaussians of different colours with centres along x, swaps the 3DGS order
// of its centres' depths at azimuth 0: the rasterizer has one event there, and it is a
// discontinuity; the sheets and the reference change continuously.
#include <catch2/catch.hpp>
#include <cmath>

#include "gaussian_pop_util.h"
#include "splat/gaussian_popping.h"
#include "splat/gaussians.h"
#include "splat/popping.h"

using namespace splat;

namespace {

// The pop scene's sweep through azimuth 0 with `slot` (the analyzer's axis slot) drawn by
// `rasterizer`, sheet by the sheets and reference by the reference.
PoppingResult sweepPop(GaussianRenderer rasterizer) {
    const GaussianScene& scene = test::popScene();
    const RenderSettings settings = test::popSettings();
    const Sweep sweep = test::popSweep(settings);
    PoppingOptions o;
    o.flip = false;
    o.refine = 8;
    o.renderFrame = [rasterizer, &scene](const RenderSettings& s, RenderStats*) {
        GaussianRenderOptions g;
        g.renderer = s.renderer == RendererKind::Axis    ? rasterizer
                     : s.renderer == RendererKind::Sheet ? GaussianRenderer::Sheet
                                                         : GaussianRenderer::Reference;
        g.slab = 0.05;
        g.tolerance = 1e-5;
        return renderGaussians(scene, s.camera, g);
    };
    return analyzePopping(scene.geometry(), settings, sweep, o);
}

// The events of the axis slot: each must lie at azimuth 0 and be a discontinuity.
int rasterEvents(const PoppingResult& r, int& others) {
    int n = 0;
    others = 0;
    for (const PoppingEvent& e : r.events) {
        if (e.renderer != RendererKind::Axis) {
            ++others;
            continue;
        }
        ++n;
        CHECK(e.angleFrom <= 0.0);
        CHECK(e.angleTo >= 0.0);
        CHECK(e.refinedAngle == Approx(0.0).margin(2 * e.refinedWidth));
        CHECK(std::abs(e.refinedSlope) < 0.2);  // the jump does not fall as the step shrinks
        CHECK(e.refinedJump > 0.01);
    }
    return n;
}

}  // namespace

TEST_CASE("Gaussian popping: 3dgs pops where the centres' depths swap, sheet does not",
          "[gaussians][popping]") {
    int others = 0;
    CHECK(rasterEvents(sweepPop(GaussianRenderer::Rasterizer), others) == 1);
    CHECK(others == 0);
}

TEST_CASE("Gaussian popping: 3dgs-pixel pops too where the Gaussians are isotropic",
          "[gaussians][popping]") {
    // On an orthographic ray t* of an isotropic Gaussian is the depth of its mean: the
    // per-pixel order swaps at azimuth 0 in every pixel at once, as the global one.
    int others = 0;
    CHECK(rasterEvents(sweepPop(GaussianRenderer::PixelSorted), others) == 1);
    CHECK(others == 0);
}

TEST_CASE("Gaussian popping: order swaps predicted where the centres' depths swap",
          "[gaussians][popping]") {
    const GaussianScene pop = syntheticGaussians("gaussians:pop");
    Sweep sweep;
    sweep.from = -5.5;
    sweep.to = 185.5;
    sweep.step = 1;
    // mu_blue - mu_red = (1.2, 0, 0) is perpendicular to the view (-sin a, cos a, 0) at
    // azimuth 0 and 180.
    const std::vector<double> swaps = predictOrderSwaps(pop, sweep);
    REQUIRE(swaps.size() == 2);
    CHECK(swaps[0] == Approx(0.0).margin(1e-8));
    CHECK(swaps[1] == Approx(180.0).margin(1e-8));
    // At elevation 60 the view still crosses the plane x = 0 at azimuth 0 and 180.
    sweep.base.elevationDeg = 60;
    CHECK(predictOrderSwaps(pop, sweep).size() == 2);
    // Moved apart beyond their footprints (3 sigma each), the two never overlap: no swap.
    GaussianScene apart = pop;
    apart.means[0].x = -3.1f;
    apart.means[1].x = 3.1f;
    CHECK(predictOrderSwaps(apart, sweep).empty());
    // A camera path through azimuth 0 (views at u = 0, 1, 2: azimuth -10, 10, 30).
    CameraPath path;
    for (double a : {-10.0, 10.0, 30.0}) {
        CameraParams c;
        c.azimuthDeg = a;
        path.views.push_back(c);
    }
    const std::vector<double> u = predictOrderSwaps(pop, path);
    REQUIRE(u.size() == 1);
    CHECK(u[0] == Approx(0.5).margin(1e-8));
}

TEST_CASE("Gaussian popping: all four renderers in one analysis, by name", "[gaussians][popping]") {
    const GaussianScene pop = syntheticGaussians("gaussians:pop");
    Sweep sweep;
    sweep.base.width = sweep.base.height = 40;
    sweep.from = -3.5;
    sweep.to = 3.5;
    sweep.step = 1;
    GaussianRenderOptions g;
    g.slab = 0.05;
    PoppingOptions o;
    o.flip = false;
    o.refine = 6;
    const PoppingResult r = analyzeGaussianPopping(
        pop, sweep, parseGaussianRenderers("3dgs,3dgs-pixel,sheet,reference"), g, o);
    REQUIRE(r.series.size() == 4);
    CHECK(r.series[0].name == "3dgs");
    CHECK(r.series[1].name == "3dgs-pixel");
    CHECK(r.series[2].name == "sheet");
    CHECK(r.series[3].name == "reference");
    REQUIRE(r.predictedSwitches.size() == 1);
    CHECK(r.predictedSwitches[0] == Approx(0.0).margin(1e-8));
    CHECK(r.options.predictedName == "order swap");
    // One event for each rasterizer, at the predicted swap and a discontinuity; none for the
    // sheets and the reference.
    std::vector<int> events(4, 0);
    for (const PoppingEvent& e : r.events) {
        ++events[e.series];
        CHECK(e.predicted);
        CHECK(e.refinedAngle == Approx(0.0).margin(2 * e.refinedWidth));
        CHECK(std::abs(e.refinedSlope) < 0.2);
    }
    CHECK(events == std::vector<int>{1, 1, 0, 0});
}

TEST_CASE("Gaussian popping: no event where no order swaps", "[gaussians][popping]") {
    // Azimuth 20..30: the two Gaussians keep their order; the precision floor keeps the
    // rasterizer's smooth change from being called an event.
    const GaussianScene pop = syntheticGaussians("gaussians:pop");
    Sweep sweep;
    sweep.base.width = sweep.base.height = 32;
    sweep.from = 20;
    sweep.to = 30;
    sweep.step = 1;
    PoppingOptions o;
    o.flip = false;
    GaussianRenderOptions g;
    g.slab = 0.05;
    const PoppingResult r =
        analyzeGaussianPopping(pop, sweep, parseGaussianRenderers("3dgs,sheet,reference"), g, o);
    CHECK(r.predictedSwitches.empty());
    CHECK(r.events.empty());
}

TEST_CASE("Gaussian popping: renderer lists", "[gaussians][popping]") {
    CHECK(parseGaussianRenderers("reference,3dgs") ==
          std::vector<GaussianRenderer>{GaussianRenderer::Reference, GaussianRenderer::Rasterizer});
    CHECK_THROWS_AS(parseGaussianRenderers("3dgs,axis"), Error);
    CHECK_THROWS_AS(parseGaussianRenderers("3dgs,3dgs"), Error);
    CHECK_THROWS_AS(parseGaussianRenderers(""), Error);
}
