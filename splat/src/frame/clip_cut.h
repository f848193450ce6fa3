#pragma once
// The exact cut face in the splatters: the reconstructed field is cut at the clip
// planes and crop box per pixel, not per voxel. Each pixel's ray is intersected with the kept
// region (model/clip_region.h) and the interval is expressed in sheet coordinates s (sheet k
// of the visiting order spans s in [k - 1/2, k + 1/2]). A sheet pixel keeps the fraction of
// its path that lies inside: its additive channels and its path length are scaled by that
// fraction (ClippedPolicy, frame/compositing.h), so a constant field keeps its colour on the
// cut face and the cut edge lies where the plane is, to within the resolution of the sheet
// contents (the image-aligned slab is cut inside; the axis-aligned sheet holds whole kernels,
// so its cut is exact only for the part of the kernels inside the slice's slab).
#include <cstdint>
#include <vector>

#include "splat/camera.h"
#include "splat/settings.h"

namespace splat {

struct SheetPlan;

class ClipCut {
  public:
    /// The cut of `clipping` for the frame's camera and sheets; empty() when the kept region
    /// contains the whole volume padded by the kernel radius `radius` (voxels): then no pixel
    /// changes.
    ClipCut(const Clipping& clipping, const Camera& camera, const SheetPlan& plan,
            const Volume& volume, double radius, bool frontToBack);

    bool empty() const { return lo_.empty(); }
    /// Kept fraction of sheet k's path at image pixel q (1 exactly when wholly inside).
    float fraction(std::size_t q, std::uint32_t k) const {
        const float a = std::max(lo_[q], float(k) - 0.5f), b = std::min(hi_[q], float(k) + 0.5f);
        return b > a ? std::min(1.0f, b - a) : 0.0f;
    }

    /// Sheet coordinate of the near end of pixel q's kept interval (front-to-back).
    float entry(std::size_t q) const { return lo_[q]; }

  private:
    std::vector<float> lo_, hi_;  // kept interval in sheet coordinates per pixel
};

}  // namespace splat
