#pragma once
// Error metrics between two images of the same size (RGB channels; alpha ignored).
#include <string>

#include "splat/image.h"

namespace splat {

struct ImageMetrics {
    double rmse = 0;    ///< over all pixels and RGB channels
    double psnr = 0;    ///< 20 log10(peak / rmse), peak = max of the reference (>= 1e-12)
    double maxAbs = 0;  ///< largest absolute channel difference
    double meanAbsForeground = 0;  ///< mean abs difference over pixels non-background in either
    std::size_t foregroundPixels = 0;
};

/// Compares `test` against `reference`; throws splat::Error if the sizes differ.
ImageMetrics compareImages(const Image& test, const Image& reference);

/// Writes |test - reference| (max over RGB) as a colour-mapped heat map (OpenImageIO's
/// "inferno" map), scaled to [0, scale] (scale <= 0: the max difference).
void writeHeatmap(const std::string& path, const Image& test, const Image& reference,
                  double scale = 0);

}  // namespace splat
