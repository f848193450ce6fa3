#pragma once
// Gaussian scenes (splat/gaussians.h) on the command line: a VOLUME argument ending in .ply
// or starting with "gaussians:" is a 3DGS scene, for `splat info` and `splat render`
// (--renderer 3dgs|3dgs-pixel|sheet|reference; the camera options apply, --slab is in world
// units); `splat gaussians VOLUME -o scene.ply` (cmd_gaussians.cpp) writes a volume's splats as
// one.
#include <CLI/CLI.hpp>
#include <string>

#include "render_options.h"

namespace splat::cli {

/// `splat info` of a Gaussian scene: count, SH degree, bounds, opacity and scale ranges.
void printGaussianInfo(const std::string& spec);
/// `splat render` of a Gaussian scene to `output`.
void renderGaussianFile(const CLI::App& cmd, const RenderArgs& args, const std::string& spec,
                        const std::string& output);

}  // namespace splat::cli
