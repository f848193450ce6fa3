#pragma once
// The compositing policy's parameters for a frame of a Scene (frame/compositing.h).
#include "frame/compositing.h"
#include "model/scene_impl.h"
#include "splat/camera.h"

namespace splat {

/// The compositing policy's parameters for a frame of `scene` seen by `camera`.
PolicyContext policyContext(const Scene::Impl& scene, const Camera& camera,
                            const RenderSettings& settings);

}  // namespace splat
