#pragma once
// The reference ray caster: one ray per pixel through the same continuous fields the
// splatters approximate, f(x) = sum_i d_i h(S^-1 (x - x_i)) (and rho, e likewise for
// pre-classification), integrated with error control. It is the ground truth every
// accuracy figure is measured against; it is allowed to be slow.
#include "footprint/kernel.h"
#include "splat/camera.h"
#include "splat/classify.h"
#include "splat/image.h"
#include "splat/settings.h"
#include "splat/volume.h"

namespace splat {

/// Renders `splats` (from classify with settings.mode/classification) as seen by `camera`.
/// Modes dvr (pre and post), xray, mip and iso (first hit of f = settings.isoLevel,
/// shaded with the gradient of f). Fills stats->referenceStep with the step used.
Image renderReference(const Volume& volume, const SplatList& splats,
                      const footprint::Kernel& kernel, const Camera& camera,
                      const RenderSettings& settings, RenderStats* stats = nullptr);

/// Iso mode only: per pixel, the world distance along the ray from Camera::ray's origin to
/// the first hit of f = settings.isoLevel in r = g = b with alpha 1; (0, 0, 0, 0) where the
/// ray misses. Same error control as renderReference.
Image renderReferenceDepth(const Volume& volume, const SplatList& splats,
                           const footprint::Kernel& kernel, const Camera& camera,
                           const RenderSettings& settings, RenderStats* stats = nullptr);

}  // namespace splat
