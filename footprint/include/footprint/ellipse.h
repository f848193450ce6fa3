#pragma once
// Elliptical footprints: how one kernel, seen along a view direction through a volume of
// (possibly anisotropic) spacing, maps screen offsets to footprint-table coordinates.
//
// A kernel lives in index space: a world point x sees h(|S^-1 (x - x_i)|). A ray
// x(t) = x_c + dx * axisX + dy * axisY + t * w (|w| = 1, t in world units) is the line
// u(t) = u0 + t v in index space, u0 = S^-1 (dx axisX + dy axisY), v = S^-1 w. Its line
// integral is
//     integral h(|u0 + t v|) dt = fp(|u0_perp|) / |v|,
// where u0_perp is u0 without its component along v (Westover 1990's footprint seen
// through an affine map). With P = S^-1 axisX, Q = S^-1 axisY and their parts P', Q'
// perpendicular to v, r^2 = |dx P' + dy Q'|^2 = a dx^2 + 2 b dx dy + c dy^2: the ellipse.
// Its tight axis-aligned bounding box {r^2 < R^2} has half extents
//     halfWidth = R sqrt(c / det), halfHeight = R sqrt(a / det), det = a c - b^2
// (computed as |P' x Q'|^2, never negative).
//
// Depth (slab sections, Mueller & Crawfis 1998): along that ray the index-space distance
// from the point of closest approach is z = |v| (t - t*), t* = -(u0 . v) / |v|^2, which is
// linear in (dx, dy): t* = tx dx + ty dy. So z = depthScale (t - tx dx - ty dy) with
// depthScale = |v| and the world-length integral between depths t0 and t1 is
// scale * (C(r, z1) - C(r, z0)).
//
// Perspective (Zwicker, Pfister, van Baar, Gross, "EWA volume splatting", IEEE
// Visualization 2001): the projective map is replaced at the splat centre by its local
// affine approximation (the Jacobian J of screen position w.r.t. world position): rays
// near the centre are taken parallel to the eye ray through the centre, w = (c - eye) /
// |c - eye|, and screen offsets map to world displacements axisX, axisY perpendicular to w
// with J axisX = (1, 0), J axisY = (0, 1). The centre pixel's value is then exact; the
// error off-centre grows with the kernel's angular size (see tests/test_ellipse.cpp).
//
// EWA resampling (Zwicker, Pfister, van Baar, Gross 2001, section 5): when a voxel projects
// to less than a pixel its footprint is narrower than the pixel spacing and the image,
// sampled at pixel centres, aliases. The resampling filter is the footprint convolved with
// a screen-space Gaussian low-pass of covariance l^2 I (pixels^2). Seeing the footprint as a
// Gaussian of variance k^2 in kernel units (k^2 = Kernel::variance()), its screen covariance
// is Sigma = k^2 M^-1, M = [[a, b], [b, c]]; the filter's is Sigma' = Sigma + l^2 I, and the
// table is read through M' = k^2 Sigma'^-1 with the amplitude times sqrt(det Sigma / det
// Sigma'), so the footprint's screen integral (its energy) is kept. For the Gaussian kernel
// this is the exact convolution (up to its C1 taper: the tabulated profile is stretched, not
// re-convolved); for other kernels it is the kernel's own profile stretched to the combined
// covariance (variance exact, shape approximate). Slab sections: the kernel with the low-pass
// added in the image plane is the Gaussian of covariance V + l^2 (screen axes), whose depth
// given a screen offset has mean g Sigma Sigma'^-1 d (g = (tx, ty)) and variance
// k^2 / depthScale^2 + g Sigma g^T - g Sigma Sigma'^-1 Sigma g^T: tx, ty and depthScale
// become those (its depth extent along the view does not change).
//
// Numerics: for strongly anisotropic spacing (1:1000) the quadratic form is nearly
// degenerate and a dx^2 + 2 b dx dy + c dy^2 in float loses up to (condition number) x
// eps; r2() evaluates the completed square a (dx + beta dy)^2 + gamma dy^2 instead, whose
// terms are non-negative (no cancellation). Renderers should use r2().
#include <glm/glm.hpp>

namespace footprint {

struct EllipticalFootprint {
    /// r^2 (index units) = a dx^2 + 2 b dx dy + c dy^2 for a screen offset (dx, dy).
    float a = 1, b = 0, c = 1;
    /// The same form as a completed square: r^2 = a (dx + beta dy)^2 + gamma dy^2,
    /// beta = b / a, gamma = det / a (accurate for very elongated ellipses).
    float beta = 0, gamma = 1;
    /// 1 / |S^-1 w|: multiplies table values to give the integral over world length.
    float scale = 1;
    /// Half extents of the tight axis-aligned bounding box of {r^2 < R^2}, screen units.
    float halfWidth = 0, halfHeight = 0;
    /// Depth in kernel units along the ray: z = depthScale * (t - (tx dx + ty dy)), where t
    /// is the world depth along w measured from the splat centre's depth and tx dx + ty dy
    /// is the depth of the ray's closest approach to the centre (for slab sections).
    float depthScale = 1, tx = 0, ty = 0;

    /// r^2 (voxels^2) at screen offset (dx, dy) from the splat centre; never negative.
    float r2(float dx, float dy) const {
        const float s = dx + beta * dy;
        return a * s * s + gamma * dy * dy;
    }
    /// Kernel-unit depth z of world depth t on the ray at screen offset (dx, dy).
    float depth(float t, float dx, float dy) const {
        return depthScale * (t - (tx * dx + ty * dy));
    }
};

/// Footprint for rays of direction `rayDir` (world; normalised internally) whose screen
/// offsets map to world displacements `axisX`, `axisY` per screen unit (orthographic:
/// right * pixelSize and up * pixelSize, or -up for y down). `spacing` is the voxel
/// spacing, `radius` the kernel radius R in voxels. Throws std::invalid_argument on
/// non-finite input, spacing <= 0, a zero ray direction, or screen axes that do not span a
/// plane transverse to the ray.
EllipticalFootprint ellipticalFootprint(const glm::dvec3& spacing, const glm::dvec3& axisX,
                                        const glm::dvec3& axisY, const glm::dvec3& rayDir,
                                        double radius);

/// The local affine approximation of a perspective projection at a splat centre (the
/// Jacobian, as in EWA splatting): for an eye at `eye`, camera basis right/up/forward
/// (unit) and an image plane at distance `focal` from the eye whose screen units are
/// `pixelSize` world units there, returns the footprint of the splat centred at `centre`.
/// Screen x grows along right and screen y along -up (row 0 at the top); (dx, dy) are
/// offsets from the projected centre (focal/pixelSize) (d.right, -d.up) / (d.forward),
/// d = centre - eye. The ray direction is w = d / |d|, and t is world distance along w
/// from the plane through the centre perpendicular to w. A centre at or behind the eye
/// plane (d.forward <= 0) gives an empty footprint (scale 0, zero extents).
EllipticalFootprint perspectiveFootprint(const glm::dvec3& spacing, const glm::dvec3& eye,
                                         const glm::dvec3& right, const glm::dvec3& up,
                                         const glm::dvec3& forward, double focal, double pixelSize,
                                         const glm::dvec3& centre, double radius);

/// EWA resampling of footprint `e` (see above): the footprint of a kernel of per-axis
/// variance `kernelVariance` (voxels^2, Kernel::variance()) convolved with a screen-space
/// Gaussian low-pass of standard deviation `lowPass` (screen units). lowPass 0 returns `e`
/// unchanged; an empty footprint (scale 0) stays empty. Throws std::invalid_argument on a
/// non-positive variance or a negative or non-finite lowPass or radius.
EllipticalFootprint ewaFootprint(const EllipticalFootprint& e, double kernelVariance,
                                 double lowPass, double radius);

}  // namespace footprint
