#pragma once
// Image files through OpenImageIO. Writes are atomic: a temporary file in the same folder,
// renamed over the target only when complete.
#include <string>

#include "splat/image.h"

namespace splat {

/// How float values become display values in 8-bit files (.png, .gif).
enum class DisplayMapping {
    Srgb,    ///< colour in [0, 1], sRGB-encoded (dvr, iso)
    Window,  ///< grey, linear map of [windowLow, windowHigh] of the red channel to [0, 1]
};

struct WriteOptions {
    DisplayMapping mapping = DisplayMapping::Srgb;
    float windowLow = 0.0f, windowHigh = 1.0f;
};

/// Writes `.png`, `.gif`, `.tif`/`.tiff` (8-bit display values, RGB) or `.exr` (float
/// RGBA, values as computed). Throws splat::Error naming the file on failure.
void writeImage(const std::string& path, const Image& image, const WriteOptions& options = {});

/// Reads any image OpenImageIO can read as float RGBA (missing alpha becomes 1).
Image readImage(const std::string& path);

/// Encodes a linear value in [0, 1] with the sRGB transfer curve.
float srgbEncode(float linear);

}  // namespace splat
