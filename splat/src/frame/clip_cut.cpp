// The exact cut face in the splatters (see clip_cut.h).
#include "frame/clip_cut.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

#include "frame/tile_driver.h"
#include "model/clip_region.h"

namespace splat {

ClipCut::ClipCut(const Clipping& clipping, const Camera& camera, const SheetPlan& plan,
                 const Volume& volume, double radius, bool frontToBack) {
    if (!clipping.enabled()) return;
    const glm::dvec3 pad = radius * volume.spacing;
    if (containsBox(clipping, volume.world(glm::dvec3(0.0)) - pad,
                    volume.world(glm::dvec3(volume.dims) - 1.0) + pad))
        return;
    // Sheet coordinate of a world point: an affine function s(x) = grad . x + offset.
    glm::dvec3 grad(0.0);
    double offset = 0;
    const double last = double(plan.sheets) - 1.0;
    if (plan.axis >= 0) {  // axis-aligned: the slice index along the axis, in visiting order
        const int m = plan.axis;
        grad[m] = 1.0 / volume.spacing[m];
        offset = -volume.origin[m] / volume.spacing[m];
        if (!plan.ascending) {
            grad = -grad;
            offset = last - offset;
        }
    } else {  // image-aligned: slab j (depth from the eye) has its centre at s = j
        grad = camera.view / double(plan.thickness);
        offset = -glm::dot(camera.eye, camera.view) / plan.thickness -
                 double(plan.depthOrigin) / plan.thickness - 0.5;
        if (!frontToBack) {
            grad = -grad;
            offset = last - offset;
        }
    }
    const int w = camera.width(), h = camera.height();
    lo_.resize(std::size_t(w) * h);
    hi_.resize(lo_.size());
    const double inf = std::numeric_limits<double>::infinity();
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x = 0; x < w; ++x) {
                const std::size_t q = std::size_t(y) * w + x;
                const Ray ray = camera.ray(x + 0.5, y + 0.5);
                double t0 = -inf, t1 = inf;
                if (!keptInterval(clipping, ray.origin, ray.dir, t0, t1)) {
                    lo_[q] = std::numeric_limits<float>::infinity();
                    hi_[q] = -lo_[q];
                    continue;
                }
                const double s0 = glm::dot(grad, ray.origin) + offset, ds = glm::dot(grad, ray.dir);
                auto at = [&](double t) {
                    if (std::isinf(t)) return ds == 0.0 ? s0 : (t > 0) == (ds > 0) ? inf : -inf;
                    return s0 + t * ds;
                };
                const double a = at(t0), b = at(t1);
                lo_[q] = float(std::min(a, b));
                hi_[q] = float(std::max(a, b));
            }
    });
}

}  // namespace splat
