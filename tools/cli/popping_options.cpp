// The sweep options of `splat popping` (see popping_options.h).
#include "popping_options.h"

#include "diagnostics.h"
#include "scene_file.h"

namespace splat::cli {

void addPoppingOptions(CLI::App& cmd, PoppingArgs& a) {
    addTableOptions(cmd, a.values, kSweepOptions);
}

std::vector<CameraParams> poppingViews(const PoppingArgs& a, const Sweep& sweep) {
    return splat::poppingViews(a.values, sweep);
}

void poppingFromArgs(const CLI::App& cmd, PoppingArgs& a, const RenderSettings& settings,
                     Sweep& sweep, PoppingOptions& o) {
    readGiven(cmd, a.values);
    asOptionUsage([&] { poppingFrom(a.values, settings, sweep, o); });
}

}  // namespace splat::cli
