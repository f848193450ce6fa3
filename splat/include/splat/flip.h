#pragma once
// LDR-FLIP: the perceptual difference between two images as a viewer flipping between
// them sees it (P. Andersson, J. Nilsson, T. Akenine-Moller, M. Oskarsson, K. Astrom and
// M. D. Fairchild, "FLIP: A Difference Evaluator for Alternating Images", HPG 2020). Per
// pixel in [0, 1]: a colour term (spatially filtered by contrast sensitivity functions in
// the YCxCz opponent space, Hunt-adjusted CIELAB, HyAB distance, remapped) raised to the
// power 1 - a feature term (differences of edges and points in the achromatic channel).
// Implemented from the paper. Viewing condition: pixels per degree of visual angle (67:
// a 0.7 m distance to a 0.7 m wide 3840-pixel monitor, the paper's default).
#include <vector>

#include "splat/image.h"

namespace splat {

struct FlipOptions {
    double pixelsPerDegree = 67.0;
};

/// Per-pixel LDR-FLIP (width * height values, row 0 on top) between `test` and
/// `reference`, both holding linear RGB (alpha ignored; values clamped to [0, 1]). Throws
/// splat::Error when the sizes differ or an image is empty.
std::vector<float> flipErrorMap(const Image& test, const Image& reference,
                                const FlipOptions& options = {});
/// The mean of flipErrorMap.
double flipMean(const Image& test, const Image& reference, const FlipOptions& options = {});
/// The same on sRGB-encoded values in [0, 1] (8-bit files as read by readImage), as the
/// paper's tool takes them.
std::vector<float> flipErrorMapSrgb(const Image& test, const Image& reference,
                                    const FlipOptions& options = {});

}  // namespace splat
