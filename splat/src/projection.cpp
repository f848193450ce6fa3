// Pipeline stage "project" (see projection.h).
#include "projection.h"

#include <tbb/parallel_for.h>

namespace splat {

ProjectedSplats projectSplats(const SplatList& splats, const Camera& camera,
                              const glm::dvec3& spacing, double radius) {
    ProjectedSplats p;
    const std::size_t n = splats.size();
    p.sx.resize(n);
    p.sy.resize(n);
    p.depth.resize(n);
    p.perspective = camera.perspective();
    // The kernel is the ellipsoid S * (ball of radius R); its extent along a unit
    // direction n is R |S n| (the support function of the ellipsoid).
    p.depthExtent = float(radius * glm::length(spacing * camera.view));
    if (!p.perspective)
        p.shared = footprint::ellipticalFootprint(spacing, camera.right * camera.pixelSize,
                                                  -camera.up * camera.pixelSize, camera.view,
                                                  radius);
    else {
        p.each.resize(n);
        p.depthPerRay.resize(n);
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
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
        }
    });
    return p;
}

}  // namespace splat
