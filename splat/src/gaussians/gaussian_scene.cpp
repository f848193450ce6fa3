// GaussianScene: validation, bounds and the camera's geometry (splat/gaussians.h).
#include <algorithm>
#include <cmath>
#include <string>

#include "splat/error.h"
#include "splat/gaussians.h"

namespace splat {

void GaussianScene::validate() const {
    const std::size_t n = means.size();
    if (shDegree < 0 || shDegree > 3)
        throw Error("Gaussian scene: SH degree " + std::to_string(shDegree) + " is not 0..3");
    if (n > kMaxGaussians)
        throw Error("Gaussian scene: " + std::to_string(n) + " Gaussians exceed the limit of " +
                    std::to_string(kMaxGaussians));
    if (scales.size() != n || rotations.size() != n || opacities.size() != n ||
        sh.size() != n * std::size_t(shCount()) * 3)
        throw Error(
            "Gaussian scene: means, scales, rotations, opacities and SH coefficients differ "
            "in count");
    auto bad = [](std::size_t i, const std::string& what) {
        throw Error("Gaussian scene: Gaussian " + std::to_string(i) + " " + what);
    };
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 m = means[i], s = scales[i];
        const glm::vec4 q = rotations[i];
        if (!std::isfinite(m.x) || !std::isfinite(m.y) || !std::isfinite(m.z))
            bad(i, "has a mean that is not finite");
        if (!(s.x > 0 && s.y > 0 && s.z > 0) || !std::isfinite(s.x) || !std::isfinite(s.y) ||
            !std::isfinite(s.z))
            bad(i, "has a scale that is not a finite number > 0");
        if (!(std::abs(glm::length(q) - 1.0f) < 1e-3f))
            bad(i, "has a rotation that is not a unit quaternion");
        if (!(opacities[i] >= 0.0f && opacities[i] <= 1.0f))
            bad(i, "has an opacity outside [0, 1]");
    }
    for (float v : sh)
        if (!std::isfinite(v)) throw Error("Gaussian scene: an SH coefficient is not finite");
}

void GaussianScene::bounds(glm::dvec3& lo, glm::dvec3& hi) const {
    if (means.empty()) {
        lo = glm::dvec3(-0.5);
        hi = glm::dvec3(0.5);
        return;
    }
    lo = glm::dvec3(INFINITY);
    hi = glm::dvec3(-INFINITY);
    for (std::size_t i = 0; i < means.size(); ++i) {
        const glm::vec3 s = scales[i];
        const double r = 3.0 * std::max({s.x, s.y, s.z});
        lo = glm::min(lo, glm::dvec3(means[i]) - r);
        hi = glm::max(hi, glm::dvec3(means[i]) + r);
    }
}

Volume GaussianScene::geometry() const {
    glm::dvec3 lo, hi;
    bounds(lo, hi);
    // One sample: centre() is the origin, the bounding sphere's diameter |dims * spacing|.
    Volume v;
    v.dims = glm::ivec3(1);
    v.spacing = glm::max(hi - lo, glm::dvec3(1e-6 * std::max(1.0, glm::length(hi - lo))));
    v.origin = 0.5 * (lo + hi);
    v.source = source;
    return v;
}

}  // namespace splat
