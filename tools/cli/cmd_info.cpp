// `splat info VOLUME`: loads the volume and prints describeVolume().
#include <cstdio>
#include <memory>

#include "commands.h"
#include "volume_options.h"

namespace splat::cli {

void registerInfo(CLI::App& app) {
    auto args = std::make_shared<VolumeArgs>();
    CLI::App* cmd = app.add_subcommand(
        "info", "print a volume's size, spacing, extent, value range and histogram");
    addVolumeOptions(*cmd, *args);
    cmd->callback([args] {
        Volume v = loadVolumeFromArgs(*args);
        std::fputs(describeVolume(v).c_str(), stdout);
    });
}

}  // namespace splat::cli
