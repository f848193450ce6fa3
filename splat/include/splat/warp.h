#pragma once
// A frame warped to another view with the exact flow of known cameras, and the temporal FLIP
// of StopThePop (Radl et al., "StopThePop: Sorted Gaussian Splatting for View-Consistent
// Real-time Rendering", ACM TOG 43(4), SIGGRAPH 2024): FLIP_k at frame t + k is the mean
// LDR-FLIP (splat/flip.h) between frame t + k and frame t warped to t + k, over the pixels
// where the warp holds.
//
// The warp of pixel (x, y) of the later frame: its ray (Camera::ray through the pixel centre)
// at the later frame's depth (splat/depth.h, the reference's median-opacity depth) is a point
// P, projected by the earlier camera to (x', y'), where the earlier frame is sampled
// bilinearly. A pixel is masked (left out of the mean) where
//   - the later frame has no depth there;
//   - (x', y') lies less than `border` pixels inside the earlier frame, or (x, y) less than
//     `border` pixels inside the later one (content that enters or leaves the view);
//   - P is occluded at the earlier view or is not what it shows: a pixel around (x', y')
//     carrying bilinear weight has no depth, or a depth farther than `depthTolerance` times
//     the bounding sphere's diameter from P's distance along that pixel's ray.
// Sample positions within 1e-6 pixels of a pixel centre read that pixel alone, so a camera
// that does not move warps a frame onto itself exactly.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "splat/camera.h"
#include "splat/flip.h"
#include "splat/image.h"

namespace splat {

struct WarpOptions {
    int border = 4;                ///< B, pixels
    double depthTolerance = 0.02;  ///< of the bounding sphere's diameter (Camera::boundingRadius)
};

struct WarpedFrame {
    /// The earlier frame seen from the later view; masked pixels hold the later frame's own
    /// pixel (so that they add no difference to FLIP's neighbourhoods).
    Image image;
    std::vector<std::uint8_t> valid;  ///< per pixel: 1 where the warp holds
    std::size_t validCount = 0;
};

/// Warps `earlier` (its depth `earlierDepth`, camera `earlierCamera`) to the view of `later`
/// (depth `laterDepth`, camera `laterCamera`). Depth images as splat/depth.h makes them.
/// Throws splat::Error when the sizes disagree.
WarpedFrame warpFrame(const Image& earlier, const Image& earlierDepth, const Camera& earlierCamera,
                      const Image& later, const Image& laterDepth, const Camera& laterCamera,
                      const WarpOptions& options = {});

/// FLIP_k of one frame pair: the mean of flipErrorMap(later, warped) over the valid pixels;
/// -1 where no pixel is valid.
double warpedFlip(const Image& later, const WarpedFrame& warped, const FlipOptions& options = {});

}  // namespace splat
