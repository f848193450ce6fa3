#pragma once
// The axis-aligned sheet-buffer splatter (Westover).
#include "frame/projection.h"
#include "frame/splatter.h"

namespace splat {

/// Index (0, 1, 2) of the volume axis most parallel to `view`.
int majorAxis(const glm::dvec3& view);

Image renderAxisAligned(const FrameInputs& in, const ProjectedSplats& proj, RenderStats* stats);

}  // namespace splat
