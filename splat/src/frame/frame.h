#pragma once
// One frame of a Scene (frame/renderer.cpp).
#include "frame/compositing.h"
#include "model/scene_impl.h"
#include "splat/camera.h"

namespace splat {

/// Throws splat::Error for settings no renderer can honour.
void validateFrame(const RenderSettings& settings);

/// Renders `settings.renderer`'s frame of `scene`; every stage runs on at most
/// settings.threads threads.
/// With `depth` (iso only): the hit depths as well (Scene::renderIsoDepth).
Image renderFrame(const Scene::Impl& scene, const RenderSettings& settings, RenderStats* stats,
                  Image* depth = nullptr);

/// The compositing policy's parameters for a frame of `scene` seen by `camera`.
PolicyContext policyContext(const Scene::Impl& scene, const Camera& camera,
                            const RenderSettings& settings);

}  // namespace splat
