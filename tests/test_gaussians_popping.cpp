// Popping of Gaussian scenes, through the popping analyzer's frame callback
// (PoppingOptions::renderFrame): the analyzer's three renderer slots carry the Gaussian
// renderers (axis -> 3dgs, sheet -> sheet, reference -> reference). The scene built to pop,
// two overlapping Gaussians of different colours with centres along x, swaps the 3DGS order
// of its centres' depths at azimuth 0: the rasterizer has one event there, and it is a
// discontinuity; the sheets and the reference change continuously.
#include <catch2/catch.hpp>
#include <cmath>

#include "splat/gaussians.h"
#include "splat/popping.h"

using namespace splat;

TEST_CASE("Gaussian popping: 3dgs pops where the centres' depths swap, sheet does not",
          "[gaussians][popping]") {
    const GaussianScene scene = syntheticGaussians("gaussians:pop");
    RenderSettings settings;
    settings.camera.width = settings.camera.height = 48;
    Sweep sweep;
    sweep.base = settings.camera;
    sweep.from = -5.5;
    sweep.to = 5.5;
    sweep.step = 1;
    PoppingOptions o;
    o.flip = false;
    o.refine = 8;
    o.renderFrame = [&](const RenderSettings& s, RenderStats*) {
        GaussianRenderOptions g;
        g.renderer = s.renderer == RendererKind::Axis    ? GaussianRenderer::Rasterizer
                     : s.renderer == RendererKind::Sheet ? GaussianRenderer::Sheet
                                                         : GaussianRenderer::Reference;
        g.slab = 0.05;
        g.tolerance = 1e-5;
        return renderGaussians(scene, s.camera, g);
    };
    const PoppingResult r = analyzePopping(scene.geometry(), settings, sweep, o);
    int rasterEvents = 0, otherEvents = 0;
    for (const PoppingEvent& e : r.events) {
        if (e.renderer != RendererKind::Axis) {
            ++otherEvents;
            continue;
        }
        ++rasterEvents;
        CHECK(e.angleFrom <= 0.0);
        CHECK(e.angleTo >= 0.0);
        CHECK(e.refinedAngle == Approx(0.0).margin(2 * e.refinedWidth));
        CHECK(std::abs(e.refinedSlope) < 0.2);  // the jump does not fall as the step shrinks
        CHECK(e.refinedJump > 0.01);
    }
    CHECK(rasterEvents == 1);
    CHECK(otherEvents == 0);
}
