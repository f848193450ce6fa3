#pragma once
// The frame pipeline: volume -> classify -> splat list -> project & bin to tiles ->
// splatter (axis-aligned | image-aligned sheets) -> compositing -> image, and the
// reference ray caster of the same model. A Renderer holds everything that does not
// depend on the view (kernel tables, splat list), so rotation sequences reuse it.
#include <glm/glm.hpp>
#include <memory>
#include <string>

#include "splat/camera.h"
#include "splat/classify.h"
#include "splat/image.h"
#include "splat/transfer.h"
#include "splat/volume.h"

namespace splat {

enum class RendererKind { Axis, Sheet, Reference };
enum class CompositeOrder { FrontToBack, BackToFront };

struct RenderSettings {
    RendererKind renderer = RendererKind::Axis;
    RenderMode mode = RenderMode::Dvr;
    CompositeOrder order = CompositeOrder::FrontToBack;
    Classification classification = Classification::Pre;
    TransferFunction transfer = TransferFunction::preset("gray-ramp");
    CameraParams camera;
    std::string kernel = "gaussian";           ///< footprint::Kernel::fromName
    double kernelSigma = 0, kernelRadius = 0;  ///< 0: the kernel's defaults
    double slab = 1.0;                         ///< image-aligned slab thickness, voxels
    /// Front-to-back early termination when opacity >= 1 - epsilon (0 disables).
    double earlyTermination = 1.0 / 256.0;
    glm::vec4 background{0.0f};  ///< premultiplied RGBA behind the volume
    double isoLevel = 0.5;       ///< iso mode: level of f (absolute density)
    Shading shading;             ///< headlight shading (pre-classified dvr)
    int threads = 0;             ///< 0: all cores
    int tileSize = 32;           ///< screen tile edge, pixels
    /// Reference ray caster: step in voxels of the first pass and the image tolerance at
    /// which step refinement stops (max abs change of any channel).
    double referenceStep = 0.25, referenceTolerance = 1e-4;
};

/// Counters of one frame.
struct RenderStats {
    double milliseconds = 0;
    std::size_t splats = 0;           ///< splats in the list
    std::size_t voxels = 0;           ///< voxels considered by classification
    std::size_t footprintPixels = 0;  ///< footprint-pixel updates
    std::size_t sheets = 0;           ///< sheets composited (summed over tiles)
    std::size_t culledSplats = 0;     ///< splats skipped by occlusion culling
    double referenceStep = 0;         ///< reference: final step (voxels)
    /// Stage times of the splatters: project, order + bin to tiles, rasterise + composite.
    double projectMs = 0, binMs = 0, tilesMs = 0;
};

class Renderer {
  public:
    /// Classifies the volume and builds the kernel tables. Throws splat::Error on
    /// impossible settings (slab <= 0, iso with a splatter, ...).
    Renderer(const Volume& volume, const RenderSettings& settings);
    ~Renderer();
    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;

    /// Renders one frame for `camera` (the settings' camera by default).
    Image render(RenderStats* stats = nullptr) const;
    Image render(const CameraParams& camera, RenderStats* stats = nullptr) const;

    const SplatList& splats() const;
    const RenderSettings& settings() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// One-shot convenience: Renderer(volume, settings).render(stats).
Image render(const Volume& volume, const RenderSettings& settings, RenderStats* stats = nullptr);

const char* toString(RendererKind);
const char* toString(RenderMode);
RendererKind parseRenderer(const std::string&);
RenderMode parseMode(const std::string&);

}  // namespace splat
