// The median-opacity depth of a Gaussian scene's reference (splat/depth.h): along each pixel
// ray the optical depth accumulated from the ray's start (t = 0, as the reference integrates)
// is the closed form tau(t) = sum_i A_i (erf(s_i (t - t*_i)) - erf(-s_i t*_i)), monotone in
// t, so t_1/2 is found by bisection.
#include "splat/depth.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "renderers.h"

namespace splat {

namespace {

constexpr double kErfReach = 4.5;  // erf is 1 to 2e-10 beyond 4.5: the ray's extent

/// tau(t) - tau(0) of the Gaussians on one ray.
double opticalDepth(const std::vector<gaussians::RayGaussian>& gs, double t) {
    double tau = 0;
    for (const gaussians::RayGaussian& g : gs)
        tau += g.amplitude * (std::erf(g.s * (t - g.tStar)) - std::erf(-g.s * g.tStar));
    return tau;
}

/// t_1/2 of one ray, or a negative number where its total opacity is below kDepthMinOpacity.
double medianOpacityDepth(const std::vector<gaussians::RayGaussian>& gs) {
    double t1 = 0;
    for (const gaussians::RayGaussian& g : gs) t1 = std::max(t1, g.tStar + kErfReach / g.s);
    const double total = -std::expm1(-opticalDepth(gs, t1));
    if (!(total >= kDepthMinOpacity)) return -1;
    const double tauHalf = -std::log1p(-0.5 * total);
    double a = 0, b = t1;
    while (b - a > 1e-9 * t1) {
        const double m = 0.5 * (a + b);
        (opticalDepth(gs, m) < tauHalf ? a : b) = m;
    }
    return 0.5 * (a + b);
}

}  // namespace

Image gaussianReferenceDepth(const GaussianScene& scene, const CameraParams& params) {
    using namespace gaussians;
    const Camera camera(params, scene.geometry());
    // Gaussians of optical depth below epsilon on a ray change its depth by at most that
    // share of its opacity: the reference's own cut at its default tolerance.
    constexpr double kEpsilon = 1e-6;
    const Projected p = project(scene, viewFrame(camera), Footprint::Volume, kEpsilon, true);
    const TileLists tiles = binToTiles(p, camera.width(), camera.height());
    Image depth(camera.width(), camera.height());
    forEachPixelRay(scene, p, tiles, camera, kEpsilon,
                    [&](int x, int y, const std::vector<RayGaussian>& gs) {
                        const double t = medianOpacityDepth(gs);
                        if (t >= 0) depth.at(x, y) = glm::vec4(float(t), float(t), float(t), 1.0f);
                    });
    return depth;
}

}  // namespace splat
