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

namespace {

// The pop scene's sweep through azimuth 0 with `slot` (the analyzer's axis slot) drawn by
// `rasterizer`, sheet by the sheets and reference by the reference.
PoppingResult sweepPop(GaussianRenderer rasterizer) {
    static const GaussianScene scene = syntheticGaussians("gaussians:pop");
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
    o.renderFrame = [rasterizer](const RenderSettings& s, RenderStats*) {
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
