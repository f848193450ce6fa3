#pragma once
// VOLUME and the options that say how to read it (shared by every subcommand), registered
// from the library's option table (splat/options.h).
#include <CLI/CLI.hpp>
#include <string>

#include "splat/options.h"
#include "splat/settings.h"
#include "splat/volume_io.h"

namespace splat::cli {

struct VolumeArgs {
    std::string spec;  ///< the VOLUME positional argument
    /// --dims, --type, --spacing, --big-endian, --header-bytes, --nan-policy,
    /// --allow-outside-data, --series, --time, --background-value, --grid, --zarr-level,
    /// --channel, bound to their flags.
    OptionValues values{kVolumeOptions};
};

/// Adds VOLUME and the volume options.
void addVolumeOptions(CLI::App& cmd, VolumeArgs& args);

/// Parses the options (UsageError on malformed ones).
LoadOptions loadOptionsFromArgs(const VolumeArgs& args);

/// An OME-Zarr VOLUME without --zarr-level is read at the level that splat's level-of-detail
/// rule picks for the view of `settings` (zarrLevelForView, docs/input-files.md "Choosing a
/// level"): sets --zarr-level to it when it is not level 0. Other volumes: nothing.
void chooseZarrLevel(VolumeArgs& args, const RenderSettings& settings);

/// Parses the options and loads the volume; throws splat::Error on bad input (OptionError,
/// a usage error, for a --time past the file's last step). Prints the
/// volume's note (what the loader assumed or changed) as warning lines.
Volume loadVolumeFromArgs(const VolumeArgs& args);

}  // namespace splat::cli
