#pragma once
// Gaussian scenes (splat/gaussians.h) on the command line: a VOLUME argument ending in .ply
// or starting with "gaussians:" is a 3DGS scene, for `splat info` and `splat render`
// (--renderer 3dgs|3dgs-pixel|sheet|reference; the camera options apply, --slab is in world
// units); `splat gaussians VOLUME -o scene.ply` (cmd_gaussians.cpp) writes a volume's splats as
// one.
#include <CLI/CLI.hpp>
#include <string>

#include "popping_options.h"
#include "render_options.h"
#include "splat/gaussians.h"

namespace splat::cli {

/// The view and quality options of a Gaussian scene, read by the library's option parser as
/// for a volume (the renderer aside: the Gaussian renderers are not volume renderers).
RenderSettings gaussianViewOf(const RenderArgs& args);
/// The Gaussian renderers' slab (--slab set by the run, else their default), reference
/// tolerance and threads from `view`.
GaussianRenderOptions gaussianRenderOptions(const CLI::App& cmd, const RenderArgs& args,
                                            const RenderSettings& view);
/// `splat info` of a Gaussian scene: count, SH degree, bounds, opacity and scale ranges.
void printGaussianInfo(const std::string& spec);
/// `splat render` of a Gaussian scene to `output`.
void renderGaussianFile(const CLI::App& cmd, const RenderArgs& args, const std::string& spec,
                        const std::string& output);
/// `splat popping` of a Gaussian scene (--renderers 3dgs,3dgs-pixel,sheet,reference; the
/// sweep or --path): the report to `report`, the summary printed.
void runGaussianPopping(const CLI::App& cmd, const RenderArgs& render, PoppingArgs& popping,
                        const std::string& spec, const std::string& report, bool quiet,
                        bool resume);
/// The popping summary table, predicted events and events (cmd_popping.cpp).
void printPoppingSummary(const PoppingResult& result);

}  // namespace splat::cli
