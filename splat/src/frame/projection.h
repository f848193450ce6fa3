#pragma once
// Pipeline stage "project": splat centres to screen positions and depths, and the
// elliptical footprint of each splat (one shared ellipse for orthographic views, a local
// affine approximation per splat for perspective ones).
#include <vector>

#include "footprint/ellipse.h"
#include "splat/camera.h"
#include "splat/classify.h"

namespace splat {

/// Inclusive pixel range covered by a splat's footprint bounding box, clamped to the
/// image; empty when x0 > x1 or y0 > y1.
struct PixelRect {
    int x0, y0, x1, y1;
    bool empty() const { return x0 > x1 || y0 > y1; }
};

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
                   double radius, ProjectedSplats& out);

}  // namespace splat
