#pragma once
// The reference ray caster as a renderer of a Scene's frames: it reads the Scene's field.
#include "model/scene_impl.h"
#include "reference/field.h"
#include "splat/camera.h"
#include "splat/image.h"
#include "splat/settings.h"

namespace splat {

inline bool isPreClassifiedDvr(const RenderSettings& s) {
    return s.mode == RenderMode::Dvr && s.classification == Classification::Pre;
}

/// The fields the reference needs for `s` and a splat list (with gradients or not).
inline FieldLayout fieldLayout(const RenderSettings& s, const SplatList& splats) {
    if (isPreClassifiedDvr(s)) return FieldLayout::Emission;
    const bool post = s.mode == RenderMode::Dvr && s.classification == Classification::Post;
    if (post && (s.shading.enabled || s.edges.enabled()) && splats.gx.size() == splats.size())
        return FieldLayout::DensityGradient;
    return FieldLayout::Density;
}

/// Renders `field` as seen by `camera` on the calling thread's arena; with `depth`, iso
/// hit depths as well (see renderReferenceDepth).
/// `gradientScale`: the splat list's G (edge enhancement). `samples`: the field samples the
/// rays took (tests of the error control).
Image renderReference(const Volume& volume, const ReferenceField& field, const Camera& camera,
                      const RenderSettings& settings, RenderStats* stats, Image* depth,
                      float gradientScale = 0, const LabelLookup* labels = nullptr,
                      std::size_t* samples = nullptr);

void validateReferenceKernel(const footprint::Kernel& kernel);

/// The automatic first step (Quality::referenceStep = 0), voxels: for dvr with panel
/// adaptivity 1.75 kernel standard deviations (sqrt of Kernel::variance) clamped to
/// [0.25, 1] (1 for the default Gaussian, 0.57 voxels), else 0.25.
double referenceStepFor(RenderMode mode, double kernelDeviation, bool panelAdaptive);

/// The reference's frame of `scene` seen by `camera`, on the calling thread's arena: the
/// Scene's field (made on first use), or for shaded scenes a field of this view's shaded
/// emission. With `depth` (iso only): the hit depths as well.
Image referenceFrame(const Scene::Impl& scene, const Camera& camera, const RenderSettings& s,
                     RenderStats& stats, Image* depth);
/// referenceFrame through the Gaussian pixel filter (Quality::pixelFilter, pixel_filter.h);
/// an iso depth image stays point-sampled (a filtered depth is no surface's depth).
Image filteredReferenceFrame(const Scene::Impl& scene, const Camera& camera,
                             const RenderSettings& s, RenderStats& stats, Image* depth);

/// The dvr median-opacity depth of referenceDepth (splat/depth.h) on the calling thread's arena.
/// `skipEmpty` false evaluates every sample, also where the field is 0 (the tests compare).
Image dvrMedianDepth(const Scene& scene, const Camera& camera, bool skipEmpty = true);

}  // namespace splat
