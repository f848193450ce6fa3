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

EllipticalFootprint ewaFootprint(const EllipticalFootprint& e, double kernelVariance,
                                 double lowPass, double radius) {
    if (!(kernelVariance > 0) || !std::isfinite(kernelVariance))
        throw std::invalid_argument("ewaFootprint: kernel variance must be positive");
    if (!(lowPass >= 0) || !std::isfinite(lowPass) || !(radius > 0) || !std::isfinite(radius))
        throw std::invalid_argument("ewaFootprint: low-pass and radius must be finite, >= 0");
    if (lowPass == 0 || e.scale == 0) return e;
    const double k2 = kernelVariance, l2 = lowPass * lowPass;
    const double a = e.a, b = e.b, c = e.c;
    const double det = a * double(e.gamma);  // a c - b^2 without cancellation
    // Sigma = k^2 M^-1, Sigma' = Sigma + l^2 I.
    const double sxx = k2 * c / det, syy = k2 * a / det, sxy = -k2 * b / det;
    const double pxx = sxx + l2, pyy = syy + l2;
    const double detS = k2 * k2 / det;
    const double detP = pxx * pyy - sxy * sxy;  // >= detS > 0 (all terms added are positive)
    EllipticalFootprint w = e;
    // M' = k^2 Sigma'^-1.
    w.a = float(k2 * pyy / detP);
    w.b = float(-k2 * sxy / detP);
    w.c = float(k2 * pxx / detP);
    w.beta = float(-sxy / pyy);
    w.gamma = float(k2 / pyy);
    w.scale = float(double(e.scale) * std::sqrt(detS / detP));
    // halfWidth = R sqrt(c' / det') = R sqrt(Sigma'_xx) / k.
    const double k = std::sqrt(k2);
    w.halfWidth = float(radius * std::sqrt(pxx) / k);
    w.halfHeight = float(radius * std::sqrt(pyy) / k);
    // Depth: u = Sigma g^T, g' = u^T Sigma'^-1, conditional variance as in the header.
    const double gx = e.tx, gy = e.ty;
    const double ux = sxx * gx + sxy * gy, uy = sxy * gx + syy * gy;
    const double qx = (pyy * ux - sxy * uy) / detP, qy = (pxx * uy - sxy * ux) / detP;
    const double ds = e.depthScale;
    const double var = k2 / (ds * ds) + (gx * ux + gy * uy) - (ux * qx + uy * qy);
    w.tx = float(qx);
    w.ty = float(qy);
    w.depthScale = float(k / std::sqrt(var));
    return w;
}

}  // namespace footprint
