#pragma once
// The sweep options of `splat popping` (--from, --to, --step, --sweep, --path, --frames,
// --renderers, --refine, --threshold-k, --threshold-floor, --ppd, --no-flip, --truth), shared
// with the
// Python module's splat.popping (splat/python), whose keywords are these options.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "splat/popping.h"

namespace splat::cli {

struct PoppingArgs {
    std::string sweep = "azimuth", renderers = "axis,sheet,reference";
    std::string path;  ///< a camera path JSON instead of the sweep (--path, over --frames views)
    int frames = 21;
    double from = 40, to = 50, step = 0.5, k = 5, floor = 2, ppd = 67;
    int refine = 10;
    bool noFlip = false;
    std::string truth = "auto";  ///< --truth: the reference the splatters are judged against
};

/// Adds the options to the group "Sweep".
void addPoppingOptions(CLI::App& cmd, PoppingArgs& args);

/// The sweep (base camera from `settings`) and options; refuses a bad sweep or value with a
/// UsageError before anything is loaded (`cmd`: which options were given). Leaves progress
/// and the frame journal unset; with --path the caller analyses the path instead.
void poppingFromArgs(const CLI::App& cmd, const PoppingArgs& args, const RenderSettings& settings,
                     Sweep& sweep, PoppingOptions& options);

/// The sweep's (or --path's) views, for poppingSettings (splat/popping.h).
std::vector<CameraParams> poppingViews(const PoppingArgs& args, const Sweep& sweep);

/// "axis,sheet" -> {Axis, Sheet}; throws splat::Error on an unknown or empty list.
std::vector<RendererKind> parseRenderers(const std::string& text);

}  // namespace splat::cli
