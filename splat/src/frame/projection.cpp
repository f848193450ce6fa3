// Pipeline stage "project" (see projection.h).
#include "projection.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace splat {

namespace {
// Pixel centres px + 0.5 within [sx - halfWidth, sx + halfWidth], clamped to the image.
PixelRect coveredPixels(float sx, float sy, const footprint::EllipticalFootprint& e, int width,
                        int height) {
    const float fx0 = std::ceil(sx - e.halfWidth - 0.5f), fx1 = std::floor(sx + e.halfWidth - 0.5f);
    const float fy0 = std::ceil(sy - e.halfHeight - 0.5f),
                fy1 = std::floor(sy + e.halfHeight - 0.5f);
    if (!(fx1 >= 0.0f) || !(fy1 >= 0.0f) || !(fx0 <= float(width - 1)) ||
        !(fy0 <= float(height - 1)))
        return {1, 1, 0, 0};
    return {int(std::max(fx0, 0.0f)), int(std::max(fy0, 0.0f)),
            int(std::min(fx1, float(width - 1))), int(std::min(fy1, float(height - 1)))};
}
}  // namespace

void projectSplats(const SplatList& splats, const Camera& camera, const glm::dvec3& spacing,
                   double radius, ProjectedSplats& p) {
    const std::size_t n = splats.size();
    p.sx.resize(n);
    p.sy.resize(n);
    p.depth.resize(n);
    p.rect.resize(n);
    p.perspective = camera.perspective();
    // The kernel is the ellipsoid S * (ball of radius R); its extent along a unit
    // direction n is R |S n| (the support function of the ellipsoid).
    p.depthExtent = float(radius * glm::length(spacing * camera.view));
    if (!p.perspective) {
        p.shared =
            footprint::ellipticalFootprint(spacing, camera.right * camera.pixelSize,
                                           -camera.up * camera.pixelSize, camera.view, radius);
        p.each.clear();
        p.depthPerRay.clear();
    } else {
        p.each.resize(n);
        p.depthPerRay.resize(n);
    }
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t s = r.begin(); s != r.end(); ++s) {
                const glm::dvec3 w(splats.x[s], splats.y[s], splats.z[s]);
                const glm::dvec3 q = camera.project(w);
                p.sx[s] = float(q.x);
                p.sy[s] = float(q.y);
                p.depth[s] = float(q.z);
                if (p.perspective) {
                    p.each[s] = footprint::perspectiveFootprint(
                        spacing, camera.eye, camera.right, camera.up, camera.view, camera.focal,
                        camera.pixelSize, w, radius);
                    p.depthPerRay[s] =
                        float(1.0 / glm::dot(glm::normalize(w - camera.eye), camera.view));
                }
                p.rect[s] = p.perspective && !(q.z > 0.0)
                                ? PixelRect{1, 1, 0, 0}
                                : coveredPixels(p.sx[s], p.sy[s], p.ellipse(s), camera.width(),
                                                camera.height());
            }
        });
}

}  // namespace splat
