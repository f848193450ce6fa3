#pragma once
// Popping analysis of 3D Gaussian Splatting scenes (docs/gaussians.md "Popping in Gaussian
// scenes"): the popping analyzer (splat/popping.h) over the Gaussian renderers
// (splat/gaussians.h), with the events predicted where the rasterizer's global order changes.
//
// The rasterizer `3dgs` sorts by the view depth of the means, z_i = (mu_i - eye) . v, v the
// unit view direction; two Gaussians swap order where z_i - z_j = (mu_i - mu_j) . v changes
// sign, in perspective and orthographic views alike (the eye cancels). A swap changes the
// image only where both footprints cover a pixel: the pairs predicted are those whose
// rasterizer footprints (3 standard deviations of the largest scale) overlap at the swap,
// where mu_i - mu_j lies in the image plane and its projected length is its 3D length:
// |mu_i - mu_j| < 3 (max scale_i + max scale_j), both opacities >= 1/255.
#include <string>
#include <vector>

#include "splat/gaussians.h"
#include "splat/popping.h"
#include "splat/sequence.h"

namespace splat {

/// A list of Gaussian renderers, "3dgs,3dgs-pixel,sheet,reference" (each at most once).
/// Throws splat::Error naming the renderers on an unknown or repeated name.
std::vector<GaussianRenderer> parseGaussianRenderers(const std::string& list);

/// The sweep angles in (from, to) where two overlapping Gaussians' centre depths swap (the
/// pairs above), sorted, to 1e-9 degrees; swaps closer than 1e-4 degrees are one.
std::vector<double> predictOrderSwaps(const GaussianScene& scene, const Sweep& sweep);
/// The path positions u (view n at u = n) where two overlapping Gaussians' depths swap.
std::vector<double> predictOrderSwaps(const GaussianScene& scene, const CameraPath& path);

/// The popping analysis of `scene` over `sweep` (sweep.base: image size, projection, the
/// other angle) with `renderers` in the analyzer's roles: 3dgs and 3dgs-pixel as splatters
/// (RendererKind::Axis), sheet as Sheet, reference as the truth; `render` gives the slab,
/// the reference's tolerance and the threads. `options`' renderers, names, renderNamed,
/// predicted and truth are set here (the reference is point-sampled); the rest applies as
/// for a volume. Throws splat::Error on bad sweeps or options, splat::Cancelled when cancelled.
PoppingResult analyzeGaussianPopping(const GaussianScene& scene, const Sweep& sweep,
                                     const std::vector<GaussianRenderer>& renderers,
                                     const GaussianRenderOptions& render, PoppingOptions options);
/// The same over a camera path (at least 3 views).
PoppingResult analyzeGaussianPopping(const GaussianScene& scene, const CameraPath& path,
                                     const std::vector<GaussianRenderer>& renderers,
                                     const GaussianRenderOptions& render, PoppingOptions options);

}  // namespace splat
