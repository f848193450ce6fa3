// `splat info VOLUME`: loads the volume and prints describeVolume().
#include <cstdio>
#include <memory>

#include "commands.h"
#include "diagnostics.h"
#include "scene_file.h"
#include "volume_options.h"

namespace splat::cli {

void registerInfo(CLI::App& app) {
    auto args = std::make_shared<VolumeArgs>();
    CLI::App* cmd = app.add_subcommand(
        "info", "print a volume's size, spacing, extent, value range and histogram");
    addVolumeOptions(*cmd, *args);
    cmd->footer(
        "Examples:\n"
        "  splat info ch2.nii.gz\n"
        "  splat info scan.raw --dims 256x256x128 --type uint16 --big-endian --spacing 1,1,2");
    cmd->callback([args, cmd] {
        prepareCommand(*cmd, {"volume"});
        loadOptionsFromArgs(*args);
        Volume v = loadVolumeFromArgs(*args);
        std::fputs(describeVolume(v).c_str(), stdout);
    });
}

}  // namespace splat::cli
