#pragma once
// Options and output shared by the volume-viewing commands (slices, mpr, cpr): the kernel of
// the reconstructed field, the window/level of medical viewers, an optional scale bar
// (annotations are off by default) and the PNG bit depth.
#include <CLI/CLI.hpp>
#include <string>

#include "splat/image.h"
#include "splat/views.h"

namespace splat::cli {

struct ViewArgs {
    std::string window;        ///< LO,HI
    std::string windowPreset;  ///< full | ct-brain | ct-soft | ct-bone | ct-lung
    double scaleBar = 0;       ///< world units; 0: none
    std::string kernel = "gaussian";
    double sigma = 0, radius = 0;
    int threads = 0, bitDepth = 8;
};

void addViewOptions(CLI::App& cmd, ViewArgs& args);

/// Refuses malformed view options before any work (UsageError).
void checkViewArgs(const ViewArgs& args);

/// Writes a view: .exr/.tif hold f as computed; .png the window (default: the volume's
/// [min, max]) with the scale bar burnt in when asked for.
void writeView(const std::string& path, Image image, const ViewArgs& args, const Volume& volume,
               double pixelSize);

/// "X,Y,Z" -> vector; throws splat::Error naming `what`.
glm::dvec3 parseVec3(const std::string& text, const std::string& what);

}  // namespace splat::cli
