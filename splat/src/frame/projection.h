#pragma once
// Pipeline stage "project": splat centres to screen positions and depths, and the
// elliptical footprint of each splat (one shared ellipse for orthographic views, a local
// affine approximation per splat for perspective ones).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "footprint/ellipse.h"
#include "footprint/kernel.h"
#include "splat/camera.h"
#include "splat/classify.h"
#include "splat/settings.h"

namespace splat {

/// Inclusive pixel range covered by a splat's footprint bounding box, clamped to the
/// image; empty when x0 > x1 or y0 > y1.
struct PixelRect {
    int x0, y0, x1, y1;
    bool empty() const { return x0 > x1 || y0 > y1; }
};

/// Pixel centres px + 0.5 within [sx - halfWidth, sx + halfWidth] (and likewise in y),
/// clamped to a width x height image.
inline PixelRect footprintRect(float sx, float sy, const footprint::EllipticalFootprint& e,
                               int width, int height) {
    const float fx0 = std::ceil(sx - e.halfWidth - 0.5f), fx1 = std::floor(sx + e.halfWidth - 0.5f);
    const float fy0 = std::ceil(sy - e.halfHeight - 0.5f),
                fy1 = std::floor(sy + e.halfHeight - 0.5f);
    if (!(fx1 >= 0.0f) || !(fy1 >= 0.0f) || !(fx0 <= float(width - 1)) ||
        !(fy0 <= float(height - 1)))
        return {1, 1, 0, 0};
    return {int(std::max(fx0, 0.0f)), int(std::max(fy0, 0.0f)),
            int(std::min(fx1, float(width - 1))), int(std::min(fy1, float(height - 1)))};
}

/// EWA resampling of the footprints (footprint::ewaFootprint): the kernel's per-axis
/// variance and the screen low-pass sigma in pixels; lowPass 0 leaves the footprints as they
/// are (bit-identical to a frame without it).
///
/// kernelScale (a merged level of `--lod auto`, lodFootprint in model/level_of_detail.h):
/// the kernel is that fraction of the level's voxel (the footprints are those of the spacing
/// times kernelScale) and its amplitude 1 / kernelScale^3, so every splat still integrates
/// to one voxel of its level. 1 leaves the footprints as they are.
struct FootprintFilter {
    double kernelVariance = 1, lowPass = 0, kernelScale = 1;
    /// The spacing the footprints are computed with: the grid's, times kernelScale.
    glm::dvec3 kernelSpacing(const glm::dvec3& spacing) const { return spacing * kernelScale; }
    footprint::EllipticalFootprint apply(const footprint::EllipticalFootprint& e,
                                         double radius) const {
        footprint::EllipticalFootprint f =
            lowPass > 0 ? footprint::ewaFootprint(e, kernelVariance, lowPass, radius) : e;
        if (kernelScale != 1) f.scale = float(f.scale / (kernelScale * kernelScale * kernelScale));
        return f;
    }
};

/// The frame's footprint filter from Quality::ewa and Quality::pixelFilter: on, or (auto) in
/// the modes where it was measured to lower the error against the pixel-filtered reference
/// (ewaAutoApplies) while a voxel of `volume` (the grid of the splats: a level of detail's)
/// covers fewer than Quality::kEwaAutoPixels pixels (voxelPixels, model/level_of_detail.h).
/// A merged level `level` > 0 of `--lod auto` (LevelOfDetail::Kind::Auto) is always low-passed (the
/// pixel filter, as EWA) and splatted with the kernel of lodFootprint (docs/speed-vs-accuracy.md
/// "Level of detail": kernel and low-pass together the level-0 kernel plus the pixel filter less
/// the pyramid's box, not the doubled kernel).
FootprintFilter footprintFilter(const footprint::Kernel& kernel, const Quality& quality,
                                RenderMode mode, const Camera& camera, const Volume& volume,
                                int level = 0);
/// Its low-pass sigma in pixels (0: off); splat::ewaLowPass (splat/render.h) for a frame.
double ewaLowPass(const Quality& quality, RenderMode mode, const Camera& camera,
                  const Volume& volume);

struct ProjectedSplats {
    std::vector<float> sx, sy;  ///< continuous pixel position of the centre
    std::vector<float> depth;   ///< world depth along the view direction
    bool perspective = false;
    footprint::EllipticalFootprint shared;             ///< orthographic: all splats
    std::vector<footprint::EllipticalFootprint> each;  ///< perspective: per splat
    std::vector<float> depthPerRay;  ///< perspective: 1 / (ray direction . view) per splat
    std::vector<PixelRect> rect;     ///< pixels the footprint's bounding box covers
    float depthExtent = 0;           ///< max |depth - centre depth| over a kernel, R |S view|

    const footprint::EllipticalFootprint& ellipse(std::size_t s) const {
        return perspective ? each[s] : shared;
    }
};

/// Projects every splat into `out` (its arrays are reused, so frames of a sequence do not
/// allocate). Screen units are pixels: x right, y down. Splats behind a perspective eye get
/// an empty rectangle.
void projectSplats(const SplatList& splats, const Camera& camera, const glm::dvec3& spacing,
                   double radius, ProjectedSplats& out, const FootprintFilter& filter = {});

/// Projects one splat at a time, for the splatters that project chunk by chunk (only the
/// splats that are not hidden yet): the same screen positions and footprints as
/// projectSplats.
class SplatProjector {
  public:
    SplatProjector(const SplatList& splats, const Camera& camera, const glm::dvec3& spacing,
                   double radius, const FootprintFilter& filter = {});
    bool perspective() const { return perspective_; }
    /// The footprint every splat shares (orthographic views).
    const footprint::EllipticalFootprint& shared() const { return shared_; }
    /// Screen position of splat `id` and (perspective) its own footprint in `*each`; returns
    /// its footprint's pixel box (empty for a perspective splat behind the eye).
    PixelRect project(std::uint32_t id, float& sx, float& sy,
                      footprint::EllipticalFootprint* each) const {
        const glm::dvec3 w = splats_.world(id);
        if (!perspective_) {
            const glm::dvec3 d = w - camera_.eye;
            sx = float(cx_ + glm::dot(d, rx_));
            sy = float(cy_ - glm::dot(d, ry_));
            return footprintRect(sx, sy, shared_, width_, height_);
        }
        return projectPerspective(w, sx, sy, *each);
    }

    /// Orthographic views: the screen positions of the splats on one volume row (that of
    /// splat `id`) are affine in their index i along the row, x = x0 + i dx, y = y0 + i dy
    /// (the same positions as project(), to double rounding before the cast to float).
    struct Row {
        double x0, y0, dx, dy;
    };
    Row row(std::uint32_t id) const {
        const glm::dvec3 d =
            splats_.origin +
            splats_.spacing * glm::dvec3(0.0, double(splats_.j[id]), double(splats_.k[id])) -
            camera_.eye;
        return {cx_ + glm::dot(d, rx_), cy_ - glm::dot(d, ry_), splats_.spacing.x * rx_.x,
                -splats_.spacing.x * ry_.x};
    }
    /// Starts loading splat `id`'s index position into the cache (binning walks the cells of
    /// a slab, which lie apart in the list when the sheets cross the volume's rows).
    void prefetch(std::uint32_t id) const {
        __builtin_prefetch(&splats_.i[id]);
        __builtin_prefetch(&splats_.j[id]);
        __builtin_prefetch(&splats_.k[id]);
    }
    PixelRect project(const Row& row, std::uint32_t id, float& sx, float& sy) const {
        const double i = double(splats_.i[id]);
        sx = float(row.x0 + i * row.dx);
        sy = float(row.y0 + i * row.dy);
        return footprintRect(sx, sy, shared_, width_, height_);
    }
    /// Orthographic views: the pixel box holding the footprint boxes of every splat centred
    /// in the index-space box [lo, hi] (voxel positions, inclusive), widened by a pixel
    /// against rounding; empty when none of them reaches the image.
    PixelRect boxOfIndexBox(const glm::ivec3& lo, const glm::ivec3& hi) const {
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        for (int c = 0; c < 8; ++c) {
            const glm::dvec3 idx(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
            const glm::dvec3 d = splats_.origin + splats_.spacing * idx - camera_.eye;
            const double x = cx_ + glm::dot(d, rx_), y = cy_ - glm::dot(d, ry_);
            x0 = std::min(x0, x);
            x1 = std::max(x1, x);
            y0 = std::min(y0, y);
            y1 = std::max(y1, y);
        }
        footprint::EllipticalFootprint e = shared_;
        e.halfWidth += float(0.5 * (x1 - x0)) + 1.0f;
        e.halfHeight += float(0.5 * (y1 - y0)) + 1.0f;
        return footprintRect(float(0.5 * (x0 + x1)), float(0.5 * (y0 + y1)), e, width_, height_);
    }

  private:
    PixelRect projectPerspective(const glm::dvec3& w, float& sx, float& sy,
                                 footprint::EllipticalFootprint& e) const;
    const SplatList& splats_;
    const Camera& camera_;
    glm::dvec3 spacing_;
    double radius_;
    FootprintFilter filter_;
    bool perspective_;
    int width_, height_;
    double cx_, cy_;
    glm::dvec3 rx_, ry_;  ///< right / pixelSize, up / pixelSize
    footprint::EllipticalFootprint shared_;
};

/// Per-pixel path-length factor of perspective rays through sheets with normal `axis`:
/// |view . axis| / |dir . axis|; empty for orthographic views.
std::vector<float> perspectivePathScale(const Camera& camera, const glm::dvec3& axis);

}  // namespace splat
