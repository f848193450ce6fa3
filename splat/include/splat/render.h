#pragma once
// Rendering in one call. The frame pipeline (splat/src/frame/renderer.cpp):
//   volume -> classify -> splat list (once, in a Scene)
//   -> shade -> project -> order (visiting keys) -> bin to tiles
//   -> splatter: cut kernels into sheets (axis-aligned | image-aligned) -> composite -> image
// and the reference ray caster of the same model. See splat/scene.h to render many views
// or several renderers from one classification.
#include <memory>

#include "splat/scene.h"
#include "splat/settings.h"

namespace splat {

/// One renderer bound to one Scene: settings.renderer from any camera.
class Renderer {
  public:
    /// Does not copy the volume: it must outlive the Renderer.
    Renderer(const Volume& volume, const RenderSettings& settings);
    /// A temporary volume is moved in and owned (see Scene).
    Renderer(Volume&& volume, const RenderSettings& settings);
    Renderer(const Volume&& volume, const RenderSettings& settings) = delete;
    Renderer(std::shared_ptr<const Volume> volume, const RenderSettings& settings);

    Image render(RenderStats* stats = nullptr) const;
    Image render(const CameraParams& camera, RenderStats* stats = nullptr) const;

    const SplatList& splats() const { return scene_.splats(); }
    const RenderSettings& settings() const { return settings_; }
    const Scene& scene() const { return scene_; }

  private:
    Scene scene_;
    RenderSettings settings_;
};

/// One-shot convenience: Renderer(volume, settings).render(stats).
Image render(const Volume& volume, const RenderSettings& settings, RenderStats* stats = nullptr);

}  // namespace splat
