// VOLUME and the options that say how to read it, shared by every subcommand.
#include "volume_options.h"

#include <cstdio>
#include <sstream>

#include "diagnostics.h"
#include "parallel.h"
#include "scene_file.h"
#include "splat/sparse_files.h"

namespace splat::cli {

void addVolumeOptions(CLI::App& cmd, VolumeArgs& args) {
    addOption(cmd, "VOLUME", args.spec,
              "volume file (.nii .nii.gz .nrrd .nhdr .mhd .mha .raw .vdb), folder of slices or "
              "DICOM files, OME-Zarr folder, or synthetic:NAME[:N] (phantom, ct-phantom, blob, "
              "cube, sphere, marschner-lobb)",
              "Volume", PathKind::Input);
    addTableOptions(cmd, args.values, kVolumeOptions);
}

LoadOptions loadOptionsFromArgs(const VolumeArgs& args) {
    return asOptionUsage([&] { return loadOptionsFrom(args.values); });
}

void chooseZarrLevel(VolumeArgs& args, const RenderSettings& settings) {
    if (!args.values.text("zarr-level").empty() || !isZarrFolder(args.spec)) return;
    const ZarrImageInfo info = describeZarr(args.spec);
    const int level = zarrLevelForView(info, settings);
    if (level == 0) return;
    args.values.set("zarr-level", std::to_string(level));
    if (!workerProcess())
        std::printf(
            "reading OME-Zarr level %d of %zu, the level of detail of this view "
            "(--zarr-level picks another)\n",
            level, info.levels.size());
}

Volume loadVolumeFromArgs(const VolumeArgs& args) {
    loadOptionsFromArgs(args);  // malformed options: usage errors, before any reading
    Volume v = loadVolumeFrom(args.spec, args.values);
    // Recorded in every image the run writes, so that a scene reproduces.
    char b[64];
    std::snprintf(b, sizeof b, "%.9g", double(v.background));
    runMetadata().push_back({"splat:background_value", std::string(b) + " (" + v.backgroundSource + ")"});
    // Every command that loads a volume says what the loader had to assume or change.
    std::string note = v.note;
    for (std::size_t at; (at = note.find("; ")) != std::string::npos;) note.replace(at, 2, "\n");
    std::string lines;
    std::istringstream in(note);
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) lines += args.spec + ": " + line + "\n";
    warn(lines);
    return v;
}

}  // namespace splat::cli
