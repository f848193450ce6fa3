#pragma once
// Volume viewing through the reconstructed field (docs/design.md "The model"): slices,
// multiplanar reconstruction (axis-aligned and oblique planes) and curved planar reformation
// along a polyline, all evaluating f(x) = sum_i d_i h(S^-1 (x - x_i)) with the reference ray
// caster's field evaluator (splat/src/reference/field.h), so that what a view shows is exactly
// the field every renderer approximates.
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

#include "splat/image.h"
#include "splat/volume.h"

namespace splat {

/// The continuous field f of a volume, evaluable at any world point.
class FieldView {
  public:
    /// Does not copy the volume: it must outlive the FieldView. Kernel as in RenderSettings.
    explicit FieldView(const Volume& volume, const std::string& kernel = "gaussian",
                       double sigma = 0, double radius = 0, int threads = 0);
    ~FieldView();
    FieldView(const FieldView&) = delete;
    FieldView& operator=(const FieldView&) = delete;

    double operator()(const glm::dvec3& world) const;
    const Volume& volume() const;
    /// The kernel's partition-of-unity ripple max |sum_i h(p - p_i) - 1|.
    double partitionOfUnityRipple() const;
    double kernelRadius() const;
    int threads() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// A cut plane seen face on: pixel (x, y) shows f at
///   point + (x + 0.5 - width / 2) pixelSize right + (height / 2 - y - 0.5) pixelSize up'
/// with right = normalize(up x normal) and up' = normal x right (for an axial plane, normal +z
/// and up +y: right is +x).
struct PlaneView {
    glm::dvec3 point{0.0}, normal{0.0, 0.0, 1.0}, up{0.0, 1.0, 0.0};
    int width = 256, height = 256;
    double pixelSize = 1.0;
};

/// f on the plane, in r = g = b (alpha 1). Throws splat::Error for a degenerate plane.
Image multiplanarReconstruction(const FieldView& field, const PlaneView& plane);

/// The axis-aligned slice `index` along `axis` (0 = x, 1 = y, 2 = z) through voxel centres,
/// one pixel per smallest spacing, covering the volume: z slices have +x right and +y up,
/// y slices +x right and +z up, x slices +y right and +z up.
PlaneView slicePlane(const Volume& volume, int axis, int index);

/// Straightened curved planar reformation along a polyline (world points): row y samples the
/// curve at arc length (y + 0.5) pixelSize from the first point; column x lies
/// (x + 0.5 - width / 2) pixelSize along the lateral direction, `lateral` made perpendicular to
/// the curve's tangent (kept from the previous point where they are parallel).
Image curvedPlanarReformation(const FieldView& field, const std::vector<glm::dvec3>& curve,
                              const glm::dvec3& lateral, int width, double pixelSize);

}  // namespace splat
