#pragma once
// The dispatcher (dispatch/render_frame.cpp): renders one frame of a Scene with the renderer
// its settings name.
#include "model/scene_impl.h"
#include "splat/image.h"
#include "splat/settings.h"

namespace splat {

/// Renders `settings.renderer`'s frame of `scene`; every stage runs on at most
/// settings.threads threads.
/// With `depth` (iso only): the hit depths as well (Scene::renderIsoDepth).
Image renderFrame(const Scene::Impl& scene, const RenderSettings& settings, RenderStats* stats,
                  Image* depth = nullptr);

}  // namespace splat
