// The compositing policy's parameters for a frame of a Scene (see policy_context.h).
#include "frame/policy_context.h"

namespace splat {

PolicyContext policyContext(const Scene::Impl& scene, const Camera& camera,
                            const RenderSettings& s) {
    PolicyContext ctx;
    ctx.mode = s.mode;
    ctx.classification = s.classification;
    ctx.transfer = &scene.transfer;
    const bool postDvr = s.mode == RenderMode::Dvr && s.classification == Classification::Post;
    ctx.gradients = postDvr && scene.needsGradients();
    ctx.shade = postDvr && s.shading.enabled;
    ctx.shading = s.shading;
    ctx.light = lightFrame(s.shading, camera.view);
    if (postDvr) ctx.edges = s.edges;
    const float g = scene.splats.gradientScale;
    ctx.invGradientScale = g > 0.0f ? 1.0f / g : 0.0f;
    // The sheets hold f - b (SplatList::background): the level is compared as level - b.
    ctx.isoLevel = float(s.isoLevel - double(scene.splats.background));
    ctx.isoColour = glm::vec3(s.transfer.sample(float(s.isoLevel)));
    if (s.mode == RenderMode::Dvr && scene.settings.labels.enabled)
        ctx.labelTable = &scene.labelTable;
    return ctx;
}

}  // namespace splat
