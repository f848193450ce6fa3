#pragma once
// The pixel-filtered reference (docs/accuracy.md "Aliasing and EWA"): the reference ray
// caster's image reconstructed through a Gaussian pixel filter,
//     I(x, y) = integral g_sigma(u - x, v - y) L(u, v) du dv / integral g_sigma,
// L the point-sampled image (one ray through each continuous screen point) and g_sigma a
// Gaussian of standard deviation sigma pixels truncated at 4 sigma along each screen axis
// (the square's outside holds 6e-5 of the weight per axis). The integral is a regular
// quadrature: s x s rays per pixel at offsets (a + 0.5) / s, over the image and a margin of
// ceil(4 sigma) pixels, weighted by g_sigma at each ray's offset from the pixel centre and
// normalised by the sum of the weights. s = 2, 4, 8, 16 until the RMS change of the filtered
// image between successive s (RGB, as compareImages), relative to the image's largest RGB
// value, is below the tolerance, or until a pass
// would trace more than 2^25 rays (then the last pass stands and its change is reported).
//
// With sigma = 0.5 (pbrt-v4's Gaussian filter) this is the antialiased image a careful user
// wants where voxels are smaller than pixels, and it is what EWA resampling in the splatters
// (footprint/ellipse.h, ewaFootprint) approximates: for X-ray images exactly, since the image
// is linear in the footprints and a Gaussian footprint convolved with g_sigma is EWA's.
#include <functional>

#include "splat/camera.h"
#include "splat/image.h"

namespace splat {

struct PixelFilterResult {
    Image image;
    int samples = 0;    ///< s: rays per pixel along each axis of the last pass
    double change = 0;  ///< relative RMS change of the last doubling of s
};

/// The view of `camera` seen through s x s rays per pixel, with the margin the filter needs:
/// the parameters of a camera whose pixel centres are the quadrature points.
CameraParams supersampledCamera(const Camera& camera, int s, int margin);

/// Filters a point-sampled image `fine` rendered with supersampledCamera(camera, s, margin)
/// into camera.width() x camera.height() pixels through g_sigma.
Image filterSupersampled(const Image& fine, int width, int height, int s, int margin,
                         double sigma);

/// The converged filtered image: `render` draws the point-sampled image of a camera's
/// parameters. Throws splat::Error for sigma outside (0, 4] or tolerance <= 0.
PixelFilterResult filteredImage(const Camera& camera, double sigma, double tolerance,
                                const std::function<Image(const CameraParams&)>& render);

}  // namespace splat
