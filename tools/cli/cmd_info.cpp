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
        // A folder of several DICOM series: list them (one is chosen with --series UID).
        if (args->values.text("series").empty()) {
            const auto series = listDicomSeries(args->spec);
            if (series.size() > 1) {
                std::printf("%s: %zu DICOM series (load one with --series UID)\n",
                            args->spec.c_str(), series.size());
                for (const auto& s : series)
                    std::printf("  %s  #%d %s %s, %zu files of %d x %d\n", s.uid.c_str(),
                                s.seriesNumber, s.modality.c_str(),
                                s.description.empty() ? "(no description)"
                                                      : ("'" + s.description + "'").c_str(),
                                s.files, s.columns, s.rows);
                return;
            }
        }
        Volume v = loadVolumeFromArgs(*args);
        std::fputs(describeVolume(v).c_str(), stdout);
    });
}

}  // namespace splat::cli
