#pragma once
// LDR-FLIP with each image perceived once (splat/flip.h): an image's CSF-filtered colour and
// feature maps made once and compared with several images, so that a frame compared with
// many (a sweep's reference, its previous view, its warped past) is filtered once. The maps
// are the ones flipErrorMap makes for every pair, so the errors are the same bit for bit.
#include <memory>
#include <vector>

#include "splat/flip.h"
#include "splat/warp.h"

namespace splat::analysis {

class FlipImage {
  public:
    /// Throws splat::Error like flipErrorMap for an empty or malformed image or bad options.
    FlipImage(const Image& image, const FlipOptions& options = {});
    struct Maps;  ///< flip.cpp: the perceived planes
    const Maps& maps() const { return *maps_; }
    int width() const { return width_; }
    int height() const { return height_; }
    double pixelsPerDegree() const { return pixelsPerDegree_; }

  private:
    std::shared_ptr<const Maps> maps_;
    int width_ = 0, height_ = 0;
    double pixelsPerDegree_ = 0;
};

/// flipErrorMap(test, reference) of the two images perceived (same size and options, else
/// splat::Error).
std::vector<float> flipErrorMap(const FlipImage& test, const FlipImage& reference);

/// Mean of that map: flipMean(test, reference).
double flipMean(const FlipImage& test, const FlipImage& reference);

/// warpedFlip(later, warped) with `later` perceived (warped: the frame warped to its view).
double warpedFlip(const FlipImage& later, const WarpedFrame& warped);

}  // namespace splat::analysis
