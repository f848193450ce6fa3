#pragma once
// The reference ray caster as a frame stage: it reads a Scene's prebuilt field.
#include "reference/field.h"
#include "splat/camera.h"
#include "splat/settings.h"

namespace splat {

inline bool isPreClassifiedDvr(const RenderSettings& s) {
    return s.mode == RenderMode::Dvr && s.classification == Classification::Pre;
}

/// Renders `field` as seen by `camera` on the calling thread's arena; with `depth`, iso
/// hit depths as well (see renderReferenceDepth).
Image renderReference(const Volume& volume, const ReferenceField& field, const Camera& camera,
                      const RenderSettings& settings, RenderStats* stats, Image* depth);

void validateReferenceKernel(const footprint::Kernel& kernel);

}  // namespace splat
