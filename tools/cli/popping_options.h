#pragma once
// The sweep options of `splat popping` (--from, --to, --step, --sweep, --path, --frames,
// --renderers, --refine, --threshold-k, --threshold-floor, --ppd, --no-flip, --no-warp-flip,
// --truth),
// registered from the library's option table (splat/options.h), where the Python module's
// splat.popping reads the same keywords.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "splat/options.h"
#include "splat/popping.h"

namespace splat::cli {

struct PoppingArgs {
    OptionValues values{kSweepOptions};  ///< bound to the flags
    /// --path: a camera path JSON analysed instead of the sweep (over --frames views).
    const std::string& path() const { return values.text("path"); }
    int frames() const { return int(values.integer("frames")); }
};

/// Adds the options to the group "Sweep".
void addPoppingOptions(CLI::App& cmd, PoppingArgs& args);

/// The sweep (base camera from `settings`) and options; refuses a bad sweep or value with a
/// UsageError before anything is loaded (`cmd`: which options were given). Leaves progress
/// and the frame journal unset; with --path the caller analyses the path instead.
void poppingFromArgs(const CLI::App& cmd, PoppingArgs& args, const RenderSettings& settings,
                     Sweep& sweep, PoppingOptions& options);

/// The sweep's (or --path's) views, for poppingSettings (splat/popping.h).
std::vector<CameraParams> poppingViews(const PoppingArgs& args, const Sweep& sweep);

}  // namespace splat::cli
