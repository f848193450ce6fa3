#pragma once
// The four Gaussian renderers over the shared stages of projection.h (splat/gaussians.h
// describes each). Every one composites front to back into premultiplied RGBA, tile by tile.
#include <cmath>

#include "projection.h"
#include "splat/image.h"

namespace splat::gaussians {

/// `3dgs`: the tile's Gaussians in global depth order.
Image rasterize(const Projected& projected, const TileLists& tiles, int width, int height);
/// `3dgs-pixel`: the same alphas sorted per pixel by t*.
Image rasterizePixelSorted(const GaussianScene& scene, const Projected& projected,
                           const TileLists& tiles, const Camera& camera);
/// `sheet`: slabs [k slab, (k + 1) slab) of view depth, each Gaussian integrated exactly.
Image renderSlabs(const GaussianScene& scene, const Projected& projected, const TileLists& tiles,
                  const Camera& camera, double slab, double epsilon);
/// `reference`: the exact integral, adaptive to `tolerance` per pixel and channel.
Image renderReference(const GaussianScene& scene, const Projected& projected,
                      const TileLists& tiles, const Camera& camera, double tolerance,
                      double epsilon);

/// Adds the premultiplied sample (colour already times alpha) behind what is composited:
/// I += T C, T *= 1 - alpha (the `under` operator of splat's compositing stage).
struct FrontToBack {
    glm::dvec3 colour{0.0};
    double transmittance = 1;
    void under(const glm::dvec3& c, double alpha) {
        colour += transmittance * c;
        transmittance *= 1 - alpha;
    }
    /// A sheet of optical depth tau and emission e: alpha = 1 - exp(-tau), C = e alpha / tau
    /// (tau -> 0: C -> e).
    void sheet(double tau, const glm::dvec3& e) {
        const double alpha = -std::expm1(-tau);
        under(tau > 0 ? e * (alpha / tau) : e, alpha);
    }
    glm::vec4 pixel() const { return {glm::vec3(colour), float(1 - transmittance)}; }
};

}  // namespace splat::gaussians
