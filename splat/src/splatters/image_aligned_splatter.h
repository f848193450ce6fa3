#pragma once
// The image-aligned sheet-buffer splatter (Mueller & Crawfis 1998).
#include "frame/projection.h"
#include "frame/splatter.h"

namespace splat {

Image renderImageAligned(const FrameInputs& in, const ProjectedSplats& proj, RenderStats* stats);

}  // namespace splat
