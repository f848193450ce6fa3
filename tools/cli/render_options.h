#pragma once
// The rendering options shared by render, rotate, bench, popping and study (docs/command-line.md),
// registered from the library's option table (splat/options.h) in the --help groups Classification,
// Camera, Renderer, Quality and Output; a scene file (--scene, scene_file.h) may hold any of them.
#include <CLI/CLI.hpp>
#include <string>

#include "splat/image_io.h"
#include "splat/options.h"
#include "splat/render.h"

namespace splat::cli {

struct RenderArgs {
    /// Every rendering option's value, bound to its flag (the Output group's only with
    /// image output).
    OptionValues values{kRenderOptions | kImageOptions};
    CLI::App* cmd = nullptr;
    /// --size as given ("512x512").
    const std::string& size() const { return values.text("size"); }
};

/// Adds the rendering options; `imageOutput`: also --window, --bit-depth and --alpha.
void addRenderOptions(CLI::App& cmd, RenderArgs& args, bool imageOutput);

/// Settings from the options (renderSettingsFrom): malformed values are UsageErrors; every
/// option the run ignores gets one warning line and is reset to its default, so the result
/// cannot depend on it; then the transfer function and labels are read.
RenderSettings settingsFromArgs(RenderArgs& args, const RenderUse& use);

/// Defaults that depend on the data: with no --tf (nor an inline one), dvr of a volume that
/// looksLikeHounsfield renders with the preset ct-hu; says so on stderr.
RenderSettings withDataDefaults(const RenderArgs& a, RenderSettings s, const Volume& volume);

/// Display mapping for 8-bit outputs: sRGB for dvr/iso; for mip/xray the --window, or
/// [0, max value of the image]. Carries this run's metadata.
WriteOptions displayOptions(const RenderArgs& args, const RenderSettings& s, const Image& image);

/// Refuses an output image name before any work: an unsupported extension (UsageError), a
/// missing folder or a folder in its place (splat::Error).
void checkImageOutput(const std::string& path);
/// The extension part of checkImageOutput.
void checkImageExtension(const std::string& path);

}  // namespace splat::cli
