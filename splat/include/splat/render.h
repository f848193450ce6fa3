#pragma once
// Rendering in one call. The splatters' frame pipeline (splat/src/splatters/splat_frame.cpp):
//   volume -> classify -> splat list (once, in a Scene)
//   -> shade -> project -> order (visiting keys) -> bin to tiles
//   -> splatter: cut kernels into sheets (axis-aligned | image-aligned) -> composite -> image
// and the reference ray caster of the same model. See splat/scene.h to render many views
// or several renderers from one classification.
#include <memory>
#include <vector>

#include "splat/camera.h"
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

/// The screen low-pass sigma, pixels, that the splatters convolve their footprints with (EWA
/// resampling, Quality::ewa) in a frame of `settings` (its mode, quality and camera) over
/// `volume` at full resolution (a level of detail's coarser grid may leave auto off); 0 where
/// EWA is off. RenderStats::ewaSigma says the same after the frame.
double ewaLowPass(const RenderSettings& settings, const Volume& volume);

/// The pixel filter sigma (pixels; 0: one ray at each pixel centre) of the reference that
/// `truth` asks for, to judge the splatters' frames of `settings` at `views` over `volume`
/// (docs/accuracy.md "Aliasing and EWA"): Point 0; Filtered the pixel filter given
/// (Quality::pixelFilter), else Quality::kEwaDefaultSigma; Auto the pixel filter given, else
/// kEwaDefaultSigma where EWA is on in any of `views` (ewaLowPass: a filtered image is judged
/// against a filtered truth), else 0. The filtered reference traces s x s rays per pixel (s
/// >= 2, converged): at least 4x the point-sampled reference's time.
double truthFilter(const RenderSettings& settings, const Volume& volume,
                   const std::vector<CameraParams>& views, Truth truth);

}  // namespace splat
