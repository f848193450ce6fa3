#pragma once
// The reference ray caster as a frame stage: it reads a Scene's prebuilt field.
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
/// `gradientScale`: the splat list's G (edge enhancement).
Image renderReference(const Volume& volume, const ReferenceField& field, const Camera& camera,
                      const RenderSettings& settings, RenderStats* stats, Image* depth,
                      float gradientScale = 0, const LabelLookup* labels = nullptr);

void validateReferenceKernel(const footprint::Kernel& kernel);

}  // namespace splat
