#pragma once
// Command-line options that say how to read VOLUME (shared by every subcommand).
#include <CLI/CLI.hpp>
#include <string>

#include "splat/volume_io.h"

namespace splat::cli {

struct VolumeArgs {
    std::string spec;                 // the VOLUME positional argument
    std::string dims, type, spacing;  // raw options as typed: "256x256x128", "uint8", "1,1,2"
    bool bigEndian = false;
    std::size_t headerBytes = 0;
    std::string nanPolicy = "error";  // error | zero
    bool allowOutsideData = false;    // NRRD/MetaImage data files outside the header's folder
    std::string series;               // DICOM SeriesInstanceUID
    std::string time;                 // time step of a time series, from 0 ("": the first)
    std::string backgroundValue;      // b: a number, "auto" (the faces rule) or "" (the loader's)
    std::string grid;                 // OpenVDB: the grid's name
    std::string level, channel;       // OME-Zarr: resolution level and channel ("": unset)
};

/// Adds VOLUME and --dims/--type/--spacing/--big-endian/--header-bytes/--nan-policy/
/// --allow-outside-data/--series/--time/--background-value/--grid/--zarr-level/--channel.
void addVolumeOptions(CLI::App& cmd, VolumeArgs& args);

/// "T" as a time step (an integer from 0); throws splat::Error naming `what` otherwise.
int parseTimeStep(const std::string& text, const std::string& what);

/// Parses the options (UsageError on malformed ones).
LoadOptions loadOptionsFromArgs(const VolumeArgs& args);

/// Parses the options and loads the volume with its background value (--background-value);
/// throws splat::Error on bad input, UsageError for a --time past the file's last step. Prints nothing and records nothing (the Python module's
/// splat.load).
Volume loadVolumeWith(const VolumeArgs& args);

/// Parses the options and loads the volume; throws splat::Error on bad input. Prints the
/// volume's note (what the loader assumed or changed) as warning lines.
Volume loadVolumeFromArgs(const VolumeArgs& args);

}  // namespace splat::cli
