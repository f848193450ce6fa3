// VOLUME and the options that say how to read it, shared by every subcommand.
#include "volume_options.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "diagnostics.h"
#include "scene_file.h"
#include "splat/error.h"
#include "technique_options.h"

namespace splat::cli {
namespace {

// "256x256x128" (also "256,256,128") -> dims; every entry a positive integer.
glm::ivec3 parseDims(const std::string& s) {
    std::string t = s;
    for (char& c : t)
        if (c == 'x' || c == 'X' || c == ',') c = ' ';
    std::istringstream in(t);
    long long v[3];
    std::string rest;
    if (!(in >> v[0] >> v[1] >> v[2]) || (in >> rest))
        throw Error("--dims '" + s + "': expected XxYxZ, e.g. 256x256x128");
    for (long long d : v)
        if (d < 1 || d > 2147483647LL)
            throw Error("--dims '" + s + "': every dimension must be between 1 and 2^31-1");
    return {int(v[0]), int(v[1]), int(v[2])};
}

glm::dvec3 parseSpacing(const std::string& s) {
    std::string t = s;
    for (char& c : t)
        if (c == ',' || c == 'x') c = ' ';
    std::istringstream in(t);
    double v[3];
    std::string rest;
    if (!(in >> v[0])) throw Error("--spacing '" + s + "': expected X,Y,Z, e.g. 1,1,2.5");
    if (!(in >> v[1])) {
        v[1] = v[2] = v[0];  // one number: isotropic
    } else if (!(in >> v[2]) || (in >> rest)) {
        throw Error("--spacing '" + s + "': expected X,Y,Z, e.g. 1,1,2.5");
    }
    for (double d : v)
        if (!std::isfinite(d) || d <= 0)
            throw Error("--spacing '" + s + "': spacings must be finite and > 0");
    return {v[0], v[1], v[2]};
}

// A level or channel number: an integer 0 .. 2^31-1.
int parseIndex(const std::string& s, const std::string& flag) {
    char* end = nullptr;
    const long long v = std::strtoll(s.c_str(), &end, 10);
    if (s.empty() || *end || v < 0 || v > 2147483647LL)
        throw Error(flag + " '" + s + "': expected an integer >= 0");
    return int(v);
}

}  // namespace

int parseTimeStep(const std::string& text, const std::string& what) {
    char* end = nullptr;
    errno = 0;
    const long long t = std::strtoll(text.c_str(), &end, 10);
    if (text.empty() || *end || errno || t < 0 || t > 2147483647LL)
        throw Error(what + " '" + text + "': expected a time step, an integer from 0");
    return int(t);
}

void addVolumeOptions(CLI::App& cmd, VolumeArgs& args) {
    const std::string g = "Volume";
    addOption(cmd, "VOLUME", args.spec,
              "volume file (.nii .nii.gz .nrrd .nhdr .mhd .mha .raw .vdb), folder of slices or "
              "DICOM files, OME-Zarr folder, or synthetic:NAME[:N] (phantom, ct-phantom, blob, "
              "cube, sphere, marschner-lobb)",
              g, PathKind::Input);
    addOption(cmd, "--dims", args.dims, "raw data: dimensions XxYxZ, e.g. 256x256x128", g);
    addOption(cmd, "--type", args.type,
              "raw data: sample type (uint8 int8 uint16 int16 uint32 int32 float32 float64)", g);
    addOption(cmd, "--spacing", args.spacing, "raw data: spacing X,Y,Z (default 1,1,1)", g);
    addFlag(cmd, "--big-endian", args.bigEndian, "raw data: samples are big-endian", g);
    addOption(cmd, "--header-bytes", args.headerBytes, "raw data: bytes to skip at the start", g)
        ->check(CLI::NonNegativeNumber);
    addOption(cmd, "--nan-policy", args.nanPolicy,
              "NaN/Inf samples: 'error' refuses the volume, 'zero' replaces them by 0", g);
    addFlag(cmd, "--allow-outside-data", args.allowOutsideData,
            "NRRD/MetaImage: allow data files outside the header's folder (absolute paths, ..)", g);
    addOption(cmd, "--series", args.series,
              "DICOM: the SeriesInstanceUID to load when a folder holds several (`splat info "
              "FOLDER` lists them)",
              g);
    addOption(cmd, "--time", args.time,
              "time series (4D NIfTI, NRRD with a time axis, a folder of 3D files, OME-Zarr t): "
              "the time step to load, from 0 (default: the first)",
              g);
    addOption(cmd, "--background-value", args.backgroundValue,
              "the field's value where nothing is (b; e.g. -1000 for CT in HU): a number, or "
              "'auto' for the median of the outer faces (default: from the file, else auto)",
              g);
    addOption(cmd, "--grid", args.grid,
              "OpenVDB: the grid to load (default: 'density', else the first float or double "
              "grid; `splat info FILE.vdb` lists them)",
              g);
    addOption(cmd, "--zarr-level", args.level,
              "OME-Zarr: the resolution level, 0 the finest (default 0; `splat info` lists them)",
              g);
    addOption(cmd, "--channel", args.channel,
              "OME-Zarr: the channel of a 4D or 5D image (default 0)", g);
}

LoadOptions loadOptionsFromArgs(const VolumeArgs& args) {
    return asUsage([&] {
        LoadOptions options;
        if (!args.dims.empty()) options.raw.dims = parseDims(args.dims);
        options.raw.type = args.type;
        if (!args.spacing.empty()) options.raw.spacing = parseSpacing(args.spacing);
        options.raw.bigEndian = args.bigEndian;
        options.raw.headerBytes = args.headerBytes;
        options.allowOutsideDataFiles = args.allowOutsideData;
        options.dicomSeries = args.series;
        options.grid = args.grid;
        if (!args.level.empty()) options.level = parseIndex(args.level, "--zarr-level");
        if (!args.channel.empty()) options.channel = parseIndex(args.channel, "--channel");
        if (!args.time.empty()) options.time = parseTimeStep(args.time, "--time");
        if (args.nanPolicy == "error")
            options.nonFinite = NonFinitePolicy::Error;
        else if (args.nanPolicy == "zero")
            options.nonFinite = NonFinitePolicy::Zero;
        else
            throw Error("--nan-policy '" + args.nanPolicy + "': expected 'error' or 'zero'");
        return options;
    });
}

Volume loadVolumeWith(const VolumeArgs& args) {
    const LoadOptions options = loadOptionsFromArgs(args);
    std::optional<float> background;
    if (!args.backgroundValue.empty() && args.backgroundValue != "auto") {
        background = asUsage([&] {
            const std::vector<double> b = parseNumbers(args.backgroundValue, "--background-value");
            if (b.size() != 1 || !(std::abs(b[0]) <= 3.0e38))
                throw Error("--background-value '" + args.backgroundValue +
                            "': expected one finite number or 'auto'");
            return float(b[0]);
        });
    }
    Volume v;
    try {
        v = loadVolume(args.spec, options);
    } catch (const OptionError& e) {  // --time past the last step: the option is wrong
        throw UsageError(e.what());
    }
    if (background) {
        v.background = *background;
        v.backgroundSource = "--background-value";
    } else if (args.backgroundValue == "auto") {
        v.background = backgroundFromFaces(v);
        v.backgroundSource = "median of the outer faces (--background-value auto)";
    }
    return v;
}

Volume loadVolumeFromArgs(const VolumeArgs& args) {
    Volume v = loadVolumeWith(args);
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
