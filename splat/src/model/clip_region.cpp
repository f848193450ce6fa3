// The kept region of a Clipping (see clip_region.h).
#include "model/clip_region.h"

#include <algorithm>
#include <cmath>

namespace splat {

bool keepsNear(const Clipping& c, const glm::dvec3& x, const glm::dvec3& margin) {
    if (c.cropBox)
        for (int a = 0; a < 3; ++a)
            if (x[a] < c.boxMin[a] - margin[a] || x[a] > c.boxMax[a] + margin[a]) return false;
    for (const ClipPlane& p : c.planes) {
        // The largest reach of the margin box along the plane normal.
        const double reach = glm::dot(glm::abs(p.normal), margin) / glm::length(p.normal);
        if (glm::dot(x - p.point, p.normal) / glm::length(p.normal) > reach) return false;
    }
    return true;
}

double clipReach(double radius) { return std::sqrt(3.0) * (radius + 0.5); }

bool containsBox(const Clipping& c, const glm::dvec3& lo, const glm::dvec3& hi) {
    for (int n = 0; n < 8; ++n) {
        const glm::dvec3 corner(n & 1 ? hi.x : lo.x, n & 2 ? hi.y : lo.y, n & 4 ? hi.z : lo.z);
        if (!c.keeps(corner)) return false;
    }
    return true;
}

bool keptInterval(const Clipping& c, const glm::dvec3& origin, const glm::dvec3& dir, double& t0,
                  double& t1) {
    auto miss = [&] {
        t0 = 1.0;
        t1 = 0.0;
        return false;
    };
    if (c.cropBox)
        for (int a = 0; a < 3; ++a) {
            if (dir[a] == 0.0) {
                if (origin[a] < c.boxMin[a] || origin[a] > c.boxMax[a]) return miss();
                continue;
            }
            double ta = (c.boxMin[a] - origin[a]) / dir[a], tb = (c.boxMax[a] - origin[a]) / dir[a];
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
        }
    for (const ClipPlane& p : c.planes) {
        // Kept: (origin + t dir - point) . normal <= 0, i.e. t (dir . n) <= (point - origin) . n.
        const double dn = glm::dot(dir, p.normal), num = glm::dot(p.point - origin, p.normal);
        if (dn > 0.0)
            t1 = std::min(t1, num / dn);
        else if (dn < 0.0)
            t0 = std::max(t0, num / dn);
        else if (num < 0.0)
            return miss();
    }
    if (!(t0 <= t1)) return miss();
    return true;
}

}  // namespace splat
