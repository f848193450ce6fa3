#include "footprint/ellipse.h"

#include <cmath>
#include <stdexcept>

namespace footprint {
namespace {

bool finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

EllipticalFootprint ellipticalFootprint(const glm::dvec3& spacing, const glm::dvec3& axisX,
                                        const glm::dvec3& axisY, const glm::dvec3& rayDir,
                                        double radius) {
    if (!finite(spacing) || !finite(axisX) || !finite(axisY) || !finite(rayDir) ||
        !std::isfinite(radius))
        throw std::invalid_argument("ellipticalFootprint: non-finite input");
    if (!(spacing.x > 0 && spacing.y > 0 && spacing.z > 0))
        throw std::invalid_argument("ellipticalFootprint: voxel spacing must be positive");
    if (!(radius > 0)) throw std::invalid_argument("ellipticalFootprint: radius must be > 0");
    const double wl = glm::length(rayDir);
    if (!(wl > 0)) throw std::invalid_argument("ellipticalFootprint: zero ray direction");
    const glm::dvec3 w = rayDir / wl;
    const glm::dvec3 inv = 1.0 / spacing;
    const glm::dvec3 v = inv * w;  // index-space ray direction per world length
    const double vl = glm::length(v);
    const glm::dvec3 vh = v / vl;
    const glm::dvec3 P = inv * axisX, Q = inv * axisY;
    const glm::dvec3 Pp = P - glm::dot(P, vh) * vh, Qp = Q - glm::dot(Q, vh) * vh;
    const double a = glm::dot(Pp, Pp), b = glm::dot(Pp, Qp), c = glm::dot(Qp, Qp);
    const glm::dvec3 cr = glm::cross(Pp, Qp);
    const double det = glm::dot(cr, cr);  // = a c - b^2 without cancellation
    if (!(det > 0) || !(a > 0) || !std::isfinite(det) || !std::isfinite(1.0 / det))
        throw std::invalid_argument(
            "ellipticalFootprint: screen axes do not span a plane transverse to the ray");

    EllipticalFootprint e;
    e.a = float(a);
    e.b = float(b);
    e.c = float(c);
    e.beta = float(b / a);
    e.gamma = float(det / a);
    e.scale = float(1.0 / vl);
    // sqrt(c / det) = |Q'| / |P' x Q'|, sqrt(a / det) = |P'| / |P' x Q'|.
    const double cl = std::sqrt(det);
    e.halfWidth = float(radius * std::sqrt(c) / cl);
    e.halfHeight = float(radius * std::sqrt(a) / cl);
    e.depthScale = float(vl);
    e.tx = float(-glm::dot(P, v) / (vl * vl));
    e.ty = float(-glm::dot(Q, v) / (vl * vl));
    return e;
}

EllipticalFootprint perspectiveFootprint(const glm::dvec3& spacing, const glm::dvec3& eye,
                                         const glm::dvec3& right, const glm::dvec3& up,
                                         const glm::dvec3& forward, double focal, double pixelSize,
                                         const glm::dvec3& centre, double radius) {
    if (!std::isfinite(focal) || !(focal > 0) || !std::isfinite(pixelSize) || !(pixelSize > 0))
        throw std::invalid_argument("perspectiveFootprint: focal and pixelSize must be > 0");
    const glm::dvec3 d = centre - eye;
    const double D = glm::dot(d, forward);
    if (!(D > 0) || !finite(d)) {
        EllipticalFootprint e;
        e.a = e.c = 1;
        e.scale = 0;
        e.halfWidth = e.halfHeight = 0;
        return e;
    }
    // Screen position xs = k (d.right) / D, ys = -k (d.up) / D, k = focal / pixelSize.
    // Gradients at the centre (rows of the Jacobian J):
    const double k = focal / pixelSize;
    const glm::dvec3 gx = k * (right / D - glm::dot(d, right) / (D * D) * forward);
    const glm::dvec3 gy = -k * (up / D - glm::dot(d, up) / (D * D) * forward);
    const glm::dvec3 w = glm::normalize(d);  // J w = 0: the eye ray through the centre
    // Right inverse of J within the plane perpendicular to w.
    const glm::dvec3 ax = glm::cross(gy, w), ay = glm::cross(w, gx);
    const glm::dvec3 axisX = ax / glm::dot(gx, ax);
    const glm::dvec3 axisY = ay / glm::dot(gy, ay);
    return ellipticalFootprint(spacing, axisX, axisY, w, radius);
}

}  // namespace footprint
