#pragma once
// The classic techniques' options (issue 13), kept apart from the shared option groups:
// shading model and light, edge enhancement, normalized iso levels, clipping, segmentation
// labels and output bit depth / alpha. addTechniqueOptions adds the flags,
// applyTechniqueSceneKey reads the same keys from a scene file, applyTechniqueArgs puts them
// into RenderSettings and prints a warning for every one that does not apply.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "splat/image_io.h"
#include "splat/settings.h"

namespace splat::cli {

struct TechniqueArgs {
    double ambient = 0.35, diffuse = 0.65, specular = 0.25, shininess = 24;
    std::string light = "camera";  ///< camera | X,Y,Z (world direction towards the light)
    std::string edges;             ///< GAIN[,EXPONENT]
    bool isoNormalized = false;
    std::vector<std::string> clipPlanes;  ///< X,Y,Z,NX,NY,NZ each
    std::string crop;                     ///< X0,Y0,Z0,X1,Y1,Z1
    std::string labelVolume, labelColors, labelNames, labels;
    double labelOpacity = 1.0;
    int bitDepth = 8;
    bool alpha = false;
    bool tfRescale = false;  ///< --tf-rescale: the function's range onto the volume's [min, max]
    CLI::App* cmd = nullptr;
};

void addTechniqueOptions(CLI::App& cmd, TechniqueArgs& args);

/// Reads one scene-file key into `args` unless its flag was given; false if the key is not a
/// technique key.
bool applyTechniqueSceneKey(const std::string& key, const nlohmann::json& value,
                            TechniqueArgs& args);

/// Puts the technique options into `s` (after the shared ones) and prints one warning line
/// per option that does not apply to the chosen mode (splat/DESIGN.md: never silence).
void applyTechniqueArgs(const TechniqueArgs& args, RenderSettings& s);

/// 16-bit and alpha PNG output.
void applyTechniqueOutput(const TechniqueArgs& args, WriteOptions& o);

/// "1,2,3" -> {1, 2, 3}; throws splat::Error naming `what`.
std::vector<double> parseNumbers(const std::string& text, const std::string& what);

}  // namespace splat::cli
