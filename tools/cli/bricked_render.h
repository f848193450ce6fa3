#pragma once
// `splat render --bricks K`, and `splat render` under `mpirun -np P` (K = P unless given):
// sort-last bricked rendering (splat/bricks.h, README "Beyond one machine").
#include <string>

#include "render_options.h"
#include "splat/bricks.h"
#include "volume_options.h"

namespace splat::cli {

/// Every process loads and renders its bricks, the group composites the frame, and rank 0
/// writes it to `output` and prints what the frame took.
void renderBrickedToFile(const VolumeArgs& volume, const RenderArgs& render,
                         RenderSettings settings, int bricks, const std::string& output,
                         BrickComposite composite = BrickComposite::Exact);

}  // namespace splat::cli
