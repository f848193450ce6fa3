#pragma once
// `splat render --bricks K`, and `splat render` under `mpirun -np P` (K = P unless given):
// sort-last bricked rendering (splat/bricks.h, README "Beyond one machine").
#include <cstdint>
#include <string>

#include "render_options.h"
#include "splat/bricks.h"
#include "volume_options.h"

namespace splat::cli {

/// Every process loads and renders its bricks, the group composites the frame, and rank 0
/// writes it to `output` and prints what the frame took. `bricks` 0: chosen from the budget
/// per process (`rankBytes`, 0: defaultRankBytes) by chooseBricks, printed on rank 0.
void renderBrickedToFile(const VolumeArgs& volume, const RenderArgs& render,
                         RenderSettings settings, int bricks, std::uint64_t rankBytes,
                         const std::string& output,
                         BrickComposite composite = BrickComposite::Exact);

}  // namespace splat::cli
