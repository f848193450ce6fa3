#pragma once
// LDR-FLIP: a per-pixel estimate, in [0, 1], of the difference an observer perceives when
// flipping back and forth between a test image and a reference image on a display.
//
//   P. Andersson, J. Nilsson, T. Akenine-Möller, M. Oskarsson, K. Åström, M. D. Fairchild,
//   "FLIP: A Difference Evaluator for Alternating Images", Proc. ACM Comput. Graph. Interact.
//   Tech. 3(2), 15:1-15:23 (High-Performance Graphics 2020). doi:10.1145/3406183
//
// Colour pipeline: both images are filtered with contrast sensitivity functions in the
// opponent space YCxCz, compared with the HyAB distance in Hunt-adjusted CIELAB and remapped
// to [0, 1] (ΔEc). Feature pipeline: edges and points found on the luminance with Gaussian
// derivative filters are compared (ΔEf). Per pixel, ΔE = ΔEc^(1 - ΔEf). The result is
// symmetric: swapping test and reference gives the same map.
#include <numbers>
#include <vector>

#include "splat/image.h"

namespace splat {

/// Pixels per degree of visual angle for an observer `distance` metres from a display
/// `displayWidth` metres wide showing `resolutionX` pixels across (paper, Sec. 3).
constexpr double flipPixelsPerDegree(double distance, double displayWidth, double resolutionX) {
    return distance * (resolutionX / displayWidth) * (std::numbers::pi / 180.0);
}

struct FlipOptions {
    /// The paper's default observer: 0.7 m from a 0.7 m wide 3840-pixel (4K) monitor, which
    /// gives ~67.02 pixels per degree. Must be finite and positive.
    double pixelsPerDegree = flipPixelsPerDegree(0.7, 0.7, 3840.0);
};

/// Per-pixel LDR-FLIP error in [0, 1] (width * height floats, row 0 on top) between `test`
/// and `reference`, both holding linear RGB (splat::Image colour as stored; alpha ignored).
/// Channel values are clamped to [0, 1]; NaN counts as 0. Identical images give exactly 0.
/// Throws splat::Error if the sizes differ, an image is empty or the options are invalid.
/// The result does not depend on the number of threads.
std::vector<float> flipErrorMap(const Image& test, const Image& reference,
                                const FlipOptions& options = {});

/// Mean of flipErrorMap (the pooling the FLIP authors recommend for a single number).
double flipMean(const Image& test, const Image& reference, const FlipOptions& options = {});

/// The same on sRGB-encoded inputs (e.g. 8-bit PNG values read by splat::readImage), as the
/// paper's reference tool takes them: each channel is clamped to [0, 1] and decoded with the
/// sRGB transfer curve (IEC 61966-2-1) before flipErrorMap.
std::vector<float> flipErrorMapSrgb(const Image& test, const Image& reference,
                                    const FlipOptions& options = {});

/// Mean of flipErrorMapSrgb.
double flipMeanSrgb(const Image& test, const Image& reference, const FlipOptions& options = {});

}  // namespace splat
