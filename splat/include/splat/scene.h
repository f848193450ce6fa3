#pragma once
// splat::Scene: the view-independent state of a volume rendering, built once and rendered
// from any number of views by any renderer (axis-aligned sheets, image-aligned sheets,
// reference ray caster). It holds the resolved transfer function, the classified splat
// list (only the voxels the transfer function keeps), the kernel and its footprint tables,
// and each renderer's own state, made when that renderer first needs it (the axis-aligned
// splatter's cells, the image-aligned one's slab-section table and slice orders, the
// reference ray caster's dense field). A Scene may be rendered from several threads at
// once (each frame takes its own workspace).
#include <memory>

#include "footprint/kernel.h"
#include "splat/classify.h"
#include "splat/image.h"
#include "splat/settings.h"
#include "splat/volume.h"

namespace splat {

class Scene {
  public:
    /// Classifies `volume` with settings.mode, .classification, .transfer, .kernel* and
    /// .shading, on settings.threads threads. Throws splat::Error (one line) on impossible
    /// settings and on volumes the loaders would refuse: no samples, non-finite spacing or
    /// origin, NaN/Inf samples; and on transfer functions that TransferFunction::validate
    /// refuses (no points, unsorted or non-finite points, unit distance outside [1e-6, 1e6]).
    Scene(std::shared_ptr<const Volume> volume, const RenderSettings& settings);
    /// Does not copy the volume: it must outlive the Scene.
    Scene(const Volume& volume, const RenderSettings& settings);
    /// A temporary volume is moved into the Scene, which then owns it (no dangling
    /// reference: `Scene scene(makeSynthetic("blob", 32), s)` is safe).
    Scene(Volume&& volume, const RenderSettings& settings);
    /// A const temporary can be neither borrowed past the statement nor moved: refused at
    /// compile time.
    Scene(const Volume&& volume, const RenderSettings& settings) = delete;
    ~Scene();
    Scene(Scene&&) noexcept;
    Scene& operator=(Scene&&) noexcept;

    /// Renders one frame. `frame` chooses the renderer, camera, order, background,
    /// threads and the per-frame Quality knobs (slab, early termination, reference step
    /// and tolerance, tile size); its scene part (mode, classification, kernel, shading,
    /// table resolutions) must equal the Scene's, or splat::Error is thrown.
    Image render(const RenderSettings& frame, RenderStats* stats = nullptr) const;
    /// Iso mode, any renderer: per pixel the world distance along the ray from Camera::ray's
    /// origin to the first hit of f = level in r (alpha 1), (0, 0, 0, 0) where the ray misses.
    Image renderIsoDepth(const RenderSettings& frame, RenderStats* stats = nullptr) const;
    /// The Scene's settings with another renderer and camera.
    Image render(RendererKind renderer, const CameraParams& camera,
                 RenderStats* stats = nullptr) const;

    const Volume& volume() const;
    /// The settings the Scene was built with, transfer function resolved to absolute values.
    const RenderSettings& settings() const;
    const SplatList& splats() const;
    const footprint::Kernel& kernel() const;

    struct Impl;  ///< the renderers' view of the Scene (splat/src/model/scene_impl.h)
    const Impl& impl() const { return *impl_; }

  private:
    RenderSettings frameSettings(const RenderSettings& frame) const;
    std::unique_ptr<Impl> impl_;
};

}  // namespace splat
