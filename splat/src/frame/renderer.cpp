// splat::Renderer: the view-independent state (kernel tables, resolved transfer function,
// splat list) and the per-frame pipeline project -> bin -> splatter -> composite.
#include <array>
#include <chrono>
#include <cmath>
#include <mutex>
#include <optional>

#include "splatters/axis_splatter.h"
#include "footprint/kernel.h"
#include "splatters/image_aligned_splatter.h"
#include "projection.h"
#include "splat/error.h"
#include "splat/reference.h"
#include "splat/render.h"

namespace splat {

struct Renderer::Impl {
    const Volume& volume;
    RenderSettings settings;
    footprint::Kernel kernel;
    std::optional<footprint::FootprintTable> table;
    std::optional<footprint::SlabTable> slabs;
    std::optional<footprint::FootprintPoly> poly;
    TransferTable transfer;
    SplatList splats;  // (k, j, i) order: sorted by slice along z
    // Copies sorted by slice along x and y, made when a view first needs them, so that the
    // splatters read the list in visiting order.
    mutable std::mutex sortMutex;
    mutable std::array<std::unique_ptr<SplatList>, 2> sorted;
    // One frame at a time uses the workspace; concurrent render() calls on one Renderer
    // are serialised.
    mutable std::mutex frameMutex;
    mutable FrameWorkspace work;

    const SplatList& sortedAlong(int axis) const {
        if (axis == 2) return splats;
        std::lock_guard<std::mutex> lock(sortMutex);
        if (!sorted[axis]) sorted[axis] = std::make_unique<SplatList>(sortedBySlice(splats, axis));
        return *sorted[axis];
    }

    Impl(const Volume& v, const RenderSettings& s)
        : volume(v), settings(s), kernel(makeKernel(s)) {}

    /// Shading is modelled only where it applies: pre-classified dvr.
    bool shaded() const {
        return settings.shading.enabled && settings.mode == RenderMode::Dvr &&
               settings.classification == Classification::Pre;
    }

    static footprint::Kernel makeKernel(const RenderSettings& s) {
        try {
            return footprint::Kernel::fromName(s.kernel, s.kernelSigma, s.kernelRadius);
        } catch (const std::invalid_argument& e) {
            throw Error(e.what());
        }
    }
};

namespace {

void validate(const Volume& v, const RenderSettings& s) {
    if (v.voxelCount() == 0 || v.data.size() != v.voxelCount())
        throw Error("volume is empty or its sample count does not match its dimensions");
    if (s.renderer != RendererKind::Reference && s.mode == RenderMode::Iso)
        throw Error("iso mode is rendered by the reference ray caster only (--renderer reference)");
    if (!(s.slab > 0) || !std::isfinite(s.slab) || s.slab > 1e4)
        throw Error("slab thickness must be a positive number of voxels (got " +
                    std::to_string(s.slab) + ")");
    if (s.renderer == RendererKind::Sheet && s.slab < 1e-3)
        throw Error("slab thickness below 0.001 voxels would need millions of sheets");
    if (!(s.earlyTermination >= 0 && s.earlyTermination < 1))
        throw Error("early termination threshold must be in [0, 1)");
    if (s.tileSize < 8 || s.tileSize > 64) throw Error("tile size must be between 8 and 64 pixels");
    if (s.threads < 0 || s.threads > 1024)
        throw Error("thread count must be between 0 (all) and 1024");
    if (!(s.referenceStep > 0) || !(s.referenceTolerance > 0))
        throw Error("reference step and tolerance must be positive");
    for (int c = 0; c < 4; ++c)
        if (!(s.background[c] >= 0 && s.background[c] <= 1))
            throw Error("background must be in [0, 1]");
}

}  // namespace

Renderer::Renderer(const Volume& volume, const RenderSettings& settings) {
    validate(volume, settings);
    impl_ = std::make_unique<Impl>(volume, settings);
    const VolumeStats st = volumeStats(volume, 1);
    impl_->settings.transfer = settings.transfer.resolved(st.minValue, st.maxValue);
    impl_->splats = classify(volume, impl_->settings.transfer, settings.mode,
                             settings.classification, impl_->kernel.radius(), impl_->shaded());
    impl_->transfer = TransferTable(impl_->settings.transfer);
    if (settings.renderer != RendererKind::Reference) {
        impl_->table.emplace(impl_->kernel);
        impl_->poly.emplace(*impl_->table);
        if (impl_->poly->maxError() > footprint::FootprintPoly::kTolerance) impl_->poly.reset();
    }
    if (settings.renderer == RendererKind::Sheet) impl_->slabs.emplace(impl_->kernel);
}

Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

const SplatList& Renderer::splats() const { return impl_->splats; }
const RenderSettings& Renderer::settings() const { return impl_->settings; }

Image Renderer::render(RenderStats* stats) const { return render(impl_->settings.camera, stats); }

Image Renderer::render(const CameraParams& params, RenderStats* stats) const {
    const auto start = std::chrono::steady_clock::now();
    const Impl& m = *impl_;
    const Camera camera(params, m.volume);
    RenderSettings settings = m.settings;
    settings.camera = params;
    RenderStats local;
    local.splats = m.splats.size();
    local.voxels = m.splats.voxels;
    Image image;
    if (settings.renderer == RendererKind::Reference) {
        if (m.shaded()) {
            SplatList lit = m.splats;
            shadeEmission(m.splats, settings.shading, camera.view, lit.r, lit.g, lit.b);
            image = renderReference(m.volume, lit, m.kernel, camera, settings, &local);
        } else {
            image = renderReference(m.volume, m.splats, m.kernel, camera, settings, &local);
        }
    } else {
        const SplatList& list = m.sortedAlong(majorAxis(camera.view));
        std::lock_guard<std::mutex> lock(m.frameMutex);
        const float *er = list.r.data(), *eg = list.g.data(), *eb = list.b.data();
        if (m.shaded()) {
            shadeEmission(list, settings.shading, camera.view, m.work.r, m.work.g, m.work.b);
            er = m.work.r.data();
            eg = m.work.g.data();
            eb = m.work.b.data();
        }
        const FrameInputs in{m.volume,
                             list,
                             camera,
                             settings,
                             *m.table,
                             m.poly ? &*m.poly : nullptr,
                             m.slabs ? &*m.slabs : nullptr,
                             m.transfer,
                             m.work,
                             er,
                             eg,
                             eb};
        const auto t0 = std::chrono::steady_clock::now();
        ProjectedSplats& proj = m.work.proj;
        projectSplats(list, camera, m.volume.spacing, m.kernel.radius(), proj);
        local.projectMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        image = settings.renderer == RendererKind::Axis ? renderAxisAligned(in, proj, &local)
                                                        : renderImageAligned(in, proj, &local);
    }
    local.milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (stats) *stats = local;
    return image;
}

Image render(const Volume& volume, const RenderSettings& settings, RenderStats* stats) {
    return Renderer(volume, settings).render(stats);
}

const char* toString(RendererKind k) {
    switch (k) {
        case RendererKind::Axis:
            return "axis";
        case RendererKind::Sheet:
            return "sheet";
        case RendererKind::Reference:
            return "reference";
    }
    return "?";
}

const char* toString(RenderMode m) {
    switch (m) {
        case RenderMode::Dvr:
            return "dvr";
        case RenderMode::Mip:
            return "mip";
        case RenderMode::Xray:
            return "xray";
        case RenderMode::Iso:
            return "iso";
    }
    return "?";
}

RendererKind parseRenderer(const std::string& s) {
    if (s == "axis") return RendererKind::Axis;
    if (s == "sheet") return RendererKind::Sheet;
    if (s == "reference") return RendererKind::Reference;
    throw Error("unknown renderer '" + s + "' (axis, sheet or reference)");
}

RenderMode parseMode(const std::string& s) {
    if (s == "dvr") return RenderMode::Dvr;
    if (s == "mip") return RenderMode::Mip;
    if (s == "xray") return RenderMode::Xray;
    if (s == "iso") return RenderMode::Iso;
    throw Error("unknown mode '" + s + "' (dvr, mip, xray or iso)");
}

}  // namespace splat
