#pragma once
// The rendering options shared by render, rotate and bench (splat/DESIGN.md "Command line"),
// including --scene FILE.json: the scene file is read first and every flag given on the
// command line overrides it.
#include <CLI/CLI.hpp>
#include <string>

#include "splat/image_io.h"
#include "splat/render.h"
#include "technique_options.h"

namespace splat::cli {

struct RenderArgs {
    std::string renderer = "axis", mode = "dvr", order = "ftb", classify = "pre";
    std::string tf = "gray-ramp", size = "512x512", projection = "ortho", kernel = "gaussian";
    std::string background = "0,0,0,0", window, scene;
    double azimuth = 0, elevation = 0, pixelSize = 0, fov = 30, slab = 1, sigma = 0, radius = 0;
    double earlyTermination = 1.0 / 256.0, isoLevel = 0.5, refStep = 0.25, refTolerance = 1e-4;
    int threads = 0, tileSize = 32;
    bool shade = false;
    // Issue 12 (study branch): perspective eye distance from the volume centre.
    double distance = 0;
    CLI::App* cmd = nullptr;
    TechniqueArgs technique;  ///< technique_options.h
};

void addRenderOptions(CLI::App& cmd, RenderArgs& args);

/// Settings from the scene file (if any) overridden by the flags given.
RenderSettings settingsFromArgs(const RenderArgs& args);

/// Display mapping for 8-bit outputs: sRGB for dvr/iso; for mip/xray the --window, or
/// [0, max value of the image].
WriteOptions displayOptions(const RenderArgs& args, const RenderSettings& s, const Image& image);

/// "512x512" -> (512, 512); throws splat::Error naming `what`.
glm::ivec2 parseSize(const std::string& text, const std::string& what);

}  // namespace splat::cli
