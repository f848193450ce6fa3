#pragma once
// The rendering options shared by render, rotate, bench, popping and study (README "Command
// line"), in the --help groups Classification, Camera, Renderer, Quality and Output; a
// scene file (--scene, scene_file.h) may hold any of them.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "splat/image_io.h"
#include "splat/render.h"
#include "technique_options.h"

namespace splat::cli {

struct RenderArgs {
    std::string renderer = "axis", mode = "dvr", order = "ftb", classify = "pre";
    std::string tf = "gray-ramp", size = "512x512", projection = "ortho", kernel = "gaussian";
    std::string background = "0,0,0,0", window;
    /// A number (absolute density) or a fraction of the volume's [min, max] ending in n.
    std::string isoLevel = "0.5n";
    nlohmann::json tfInline;  ///< a transfer function given inline in a scene file
    double azimuth = 0, elevation = 0, pixelSize = 0, fov = 30, slab = 1, sigma = 0, radius = 0;
    std::string eye, lookAt, up;  // free camera: X,Y,Z world (--eye with --look-at, --up)
    double earlyTermination = 1.0 / 256.0, refStep = 0, refTolerance = 1e-4;
    double pixelFilter = 0;
    std::string ewa = "auto";
    std::string lod = "0";  ///< pixels per voxel, or "auto"
    int threads = 0, tileSize = 32;
    bool shade = false;
    double distance = 0;  ///< perspective eye distance from the volume centre (0: fit)
    CLI::App* cmd = nullptr;
    TechniqueArgs technique;  ///< technique_options.h
};

/// What a command does with its frames, for the options that only some runs use.
struct RenderUse {
    /// False when the command chooses its renderers itself (popping, study).
    bool oneRenderer = true;
    /// Extension of the images written (".png", ".exr", ...); "" when none are.
    std::string imageExt;
};

/// Adds the rendering options; `imageOutput`: also --window, --bit-depth and --alpha.
void addRenderOptions(CLI::App& cmd, RenderArgs& args, bool imageOutput);

/// Settings from the options: malformed values are UsageErrors; every option the run
/// ignores gets one warning line and is reset to its default (ignored_flags.cpp), so the
/// result cannot depend on it; then the transfer function and labels are read.
RenderSettings settingsFromArgs(RenderArgs& args, const RenderUse& use);

/// Display mapping for 8-bit outputs: sRGB for dvr/iso; for mip/xray the --window, or
/// [0, max value of the image]. Carries this run's metadata.
/// Defaults that depend on the data: with no --tf (nor an inline one), dvr of a volume that
/// looksLikeHounsfield renders with the preset ct-hu; says so on stderr.
RenderSettings withDataDefaults(const RenderArgs& a, RenderSettings s, const Volume& volume);
/// A free camera's look-at point left unset (NaN) becomes the volume's centre.
RenderSettings withFreeCameraTarget(RenderSettings s, const Volume& volume);

WriteOptions displayOptions(const RenderArgs& args, const RenderSettings& s, const Image& image);

/// Refuses an output image name before any work: an unsupported extension (UsageError), a
/// missing folder or a folder in its place (splat::Error).
void checkImageOutput(const std::string& path);
/// The extension part of checkImageOutput.
void checkImageExtension(const std::string& path);

/// "512x512" -> (512, 512); throws splat::Error naming `what`.
glm::ivec2 parseSize(const std::string& text, const std::string& what);

/// "0.4n" -> (0.4, true); "120" -> (120, false); throws splat::Error otherwise.
std::pair<double, bool> parseIsoLevel(const std::string& text);

/// Every option that the run ignores: one warning line each, and reset to its default
/// (ignored_flags.cpp). `s`: the settings parsed from `args`.
void dropIgnoredOptions(RenderArgs& args, const RenderSettings& s, const RenderUse& use);

}  // namespace splat::cli
