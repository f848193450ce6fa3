#pragma once
// Per-pixel depth of the reference renderers' images, for warping one frame to another view
// (the popping analysis's temporal FLIP, splat/popping.h). A volume rendering has no single
// surface, so a pixel's depth is the depth of its median opacity:
//
//   t_1/2 such that  1 - exp(-tau(t_1/2)) = (1 - exp(-tau_inf)) / 2,   tau(t) = int_0^t rho,
//
// the ray parameter (world distance along Camera::ray's direction from its origin) where the
// accumulated opacity reaches half the ray's total opacity. Pixels whose total opacity
// 1 - exp(-tau_inf) is below kDepthMinOpacity have no depth. Images hold t_1/2 in r, g and b
// with alpha 1 where a pixel has a depth, (0, 0, 0, 0) where not.
#include "splat/camera.h"
#include "splat/gaussians.h"
#include "splat/image.h"
#include "splat/scene.h"

namespace splat {

/// Pixels of lower total opacity have no depth.
inline constexpr double kDepthMinOpacity = 0.1;

/// The median-opacity depth of a volume Scene's reference (dvr: the extinction of its
/// classification, pre or post, marched at half the smallest spacing with the
/// optical depth integrated by the trapezoid rule, the crossing interpolated linearly within
/// the step; iso: the first hit of the level, Scene::renderIsoDepth). mip and xray have no
/// depth: an empty image (every pixel (0, 0, 0, 0)).
Image referenceDepth(const Scene& scene, const CameraParams& camera);

/// The median-opacity depth of a Gaussian scene's `reference` (splat/gaussians.h: the optical
/// depth along a ray is a closed form, tau(t) = sum_i A_i (1 + erf(s_i (t - t*_i))), and
/// t_1/2 is found by bisection to 1e-9 of the ray's extent).
Image gaussianReferenceDepth(const GaussianScene& scene, const CameraParams& camera);

}  // namespace splat
