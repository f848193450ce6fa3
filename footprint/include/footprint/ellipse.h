#pragma once
// Elliptical footprints: how one kernel, seen along a view direction through a volume of
// (possibly anisotropic) spacing, maps screen offsets to footprint-table coordinates.
//
// A kernel lives in index space: a world point x sees h(|S^-1 (x - x_i)|). A ray
// x(t) = x_c + dx * axisX + dy * axisY + t * w (|w| = 1, t in world units) is the line
// u(t) = u0 + t v in index space, u0 = S^-1 (dx axisX + dy axisY), v = S^-1 w. Its line
// integral is fp(|u0_perp|) / |v|, where u0_perp is u0 without its component along v.
// |u0_perp|^2 is a quadratic form in (dx, dy): the ellipse.
#include <glm/glm.hpp>

namespace footprint {

struct EllipticalFootprint {
    /// r^2 (index units) = a dx^2 + 2 b dx dy + c dy^2 for a screen offset (dx, dy).
    float a = 1, b = 0, c = 1;
    /// 1 / |S^-1 w|: multiplies table values to give the integral over world length.
    float scale = 1;
    /// Half extents of the tight axis-aligned bounding box of {r^2 < R^2}, screen units.
    float halfWidth = 0, halfHeight = 0;
    /// Depth in kernel units along the ray: z = depthScale * (t - (tx dx + ty dy)), where t
    /// is the world depth along w measured from the splat centre's depth and tx dx + ty dy
    /// is the depth of the ray's closest approach to the centre (for slab sections).
    float depthScale = 1, tx = 0, ty = 0;
};

/// Footprint for rays of direction `rayDir` (unit, world) whose screen offsets map to
/// world displacements `axisX`, `axisY` per screen unit (orthographic: right * pixelSize
/// and up * pixelSize, or -up for y down). `spacing` is the voxel spacing, `radius` the
/// kernel radius R in voxels.
EllipticalFootprint ellipticalFootprint(const glm::dvec3& spacing, const glm::dvec3& axisX,
                                        const glm::dvec3& axisY, const glm::dvec3& rayDir,
                                        double radius);

/// The local affine approximation of a perspective projection at a splat centre (the
/// Jacobian, as in EWA splatting): for an eye at `eye`, camera basis right/up/forward
/// (unit) and an image plane at distance `focal` from the eye whose screen units are
/// `pixelSize` world units there, returns the footprint of the splat centred at `centre`.
/// Screen x grows along right and screen y along -up (row 0 at the top).
EllipticalFootprint perspectiveFootprint(const glm::dvec3& spacing, const glm::dvec3& eye,
                                         const glm::dvec3& right, const glm::dvec3& up,
                                         const glm::dvec3& forward, double focal,
                                         double pixelSize, const glm::dvec3& centre,
                                         double radius);

}  // namespace footprint
