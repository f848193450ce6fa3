// Scene::render, Renderer and render(): a Scene's frames, checked against the Scene
// (Scene::frameSettings) and drawn by the dispatcher.
#include "dispatch/dispatch.h"
#include "splat/error.h"
#include "splat/render.h"

namespace splat {

Image Scene::render(const RenderSettings& frame, RenderStats* stats) const {
    return renderFrame(*impl_, frameSettings(frame), stats);
}

Image Scene::renderIsoDepth(const RenderSettings& frame, RenderStats* stats) const {
    const RenderSettings s = frameSettings(frame);
    if (s.mode != RenderMode::Iso) throw Error("scene: hit depths exist only in iso mode");
    Image depth;
    renderFrame(*impl_, s, stats, &depth);
    return depth;
}

Image Scene::render(RendererKind renderer, const CameraParams& camera, RenderStats* stats) const {
    RenderSettings s = impl_->settings;
    s.renderer = renderer;
    s.camera = camera;
    return renderFrame(*impl_, s, stats);
}

Renderer::Renderer(const Volume& volume, const RenderSettings& settings)
    : scene_(volume, settings), settings_(scene_.settings()) {
    settings_.renderer = settings.renderer;
}

Renderer::Renderer(Volume&& volume, const RenderSettings& settings)
    : Renderer(std::make_shared<const Volume>(std::move(volume)), settings) {}

Renderer::Renderer(std::shared_ptr<const Volume> volume, const RenderSettings& settings)
    : scene_(std::move(volume), settings), settings_(scene_.settings()) {
    settings_.renderer = settings.renderer;
}

Image Renderer::render(RenderStats* stats) const { return scene_.render(settings_, stats); }

Image Renderer::render(const CameraParams& camera, RenderStats* stats) const {
    RenderSettings s = settings_;
    s.camera = camera;
    return scene_.render(s, stats);
}

Image render(const Volume& volume, const RenderSettings& settings, RenderStats* stats) {
    return Renderer(volume, settings).render(stats);
}

}  // namespace splat
