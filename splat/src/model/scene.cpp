// splat::Scene: the model of a volume rendering (the view-independent state, built once) and
// the rule for what a frame may change. Its frames are rendered by dispatch/.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>

#include "model/clip_region.h"
#include "model/level_of_detail.h"
#include "model/scene_impl.h"
#include "splat/error.h"

namespace splat {

namespace {

footprint::Kernel makeKernel(const RenderSettings& s) {
    try {
        return footprint::Kernel::fromName(s.kernel, s.kernelSigma, s.kernelRadius);
    } catch (const std::invalid_argument& e) {
        throw Error(e.what());
    }
}

/// The footprint table of `kernel` at the quality's resolution. The last one built is kept
/// and copied: a frame of many bricks builds one Scene per brick with the same kernel.
footprint::FootprintTable makeTable(const footprint::Kernel& kernel, const Quality& q) {
    static std::mutex mutex;
    static std::optional<std::tuple<footprint::KernelType, double, double, int>> lastKey;
    static std::optional<footprint::FootprintTable> last;
    const auto key =
        std::make_tuple(kernel.type(), kernel.sigma(), kernel.radius(), q.footprintResolution);
    {
        const std::lock_guard<std::mutex> lock(mutex);
        if (last && lastKey == key) return *last;
    }
    try {
        footprint::FootprintTable table(kernel, q.footprintResolution);
        const std::lock_guard<std::mutex> lock(mutex);
        last = table;
        lastKey = key;
        return table;
    } catch (const std::invalid_argument& e) {
        throw Error(std::string("footprint table: ") + e.what());
    }
}

/// The polynomial fit of makeTable's table (footprint/footprint_poly.h), the last one kept
/// and copied likewise.
footprint::FootprintPoly makePoly(const footprint::FootprintTable& table,
                                  const footprint::Kernel& kernel, const Quality& q) {
    static std::mutex mutex;
    static std::optional<std::tuple<footprint::KernelType, double, double, int>> lastKey;
    static std::optional<footprint::FootprintPoly> last;
    const auto key =
        std::make_tuple(kernel.type(), kernel.sigma(), kernel.radius(), q.footprintResolution);
    {
        const std::lock_guard<std::mutex> lock(mutex);
        if (last && lastKey == key) return *last;
    }
    footprint::FootprintPoly poly(table);
    const std::lock_guard<std::mutex> lock(mutex);
    last = poly;
    lastKey = key;
    return poly;
}

/// Largest ratio between a volume's largest and smallest spacing a renderer accepts: beyond
/// it, slab counts and float depths lose all meaning (1e-30,1,1 or 1e-6,1,1e6 spacings).
constexpr double kMaxSpacingRatio = 1e4;
/// Largest world coordinate (origin plus extent) a renderer accepts: float depths keep
/// sub-voxel precision well inside it.
constexpr double kMaxWorldCoordinate = 1e9;

void validateGeometry(const Volume& v) {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(v.spacing[a]) || !(v.spacing[a] > 0))
            throw Error("volume spacing must be finite and > 0");
    if (!std::isfinite(v.origin.x) || !std::isfinite(v.origin.y) || !std::isfinite(v.origin.z))
        throw Error(
            "volume origin is NaN or Inf (check the file's sform/qform, space origin or "
            "Offset)");
    // The Camera turns world into the volume's frame by direction^T: a rotation only.
    const glm::dmat3 dd = glm::transpose(v.direction) * v.direction;
    double offOrthonormal = 0;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            offOrthonormal = std::max(offOrthonormal, std::abs(dd[c][r] - (c == r ? 1.0 : 0.0)));
    if (!(offOrthonormal < 1e-6) || !(glm::determinant(v.direction) > 0))
        throw Error("volume direction must be a rotation (orthonormal, determinant +1)");
    const double hi = std::max(v.spacing.x, std::max(v.spacing.y, v.spacing.z));
    if (hi / v.minSpacing() > kMaxSpacingRatio)
        throw Error("volume spacing " + std::to_string(v.spacing.x) + ", " +
                    std::to_string(v.spacing.y) + ", " + std::to_string(v.spacing.z) +
                    ": the ratio of largest to smallest exceeds 10000:1, which no renderer can "
                    "sample; check the spacing");
    for (int a = 0; a < 3; ++a)
        if (std::abs(v.origin[a]) + v.spacing[a] * double(v.dims[a]) > kMaxWorldCoordinate)
            throw Error("volume coordinates exceed 1e9 world units (origin " +
                        std::to_string(v.origin[a]) + " on axis " + std::to_string(a) +
                        "); check the origin and spacing");
}

void validateScene(const Volume& v, const RenderSettings& s) {
    if (!v.hasSamples())
        throw Error("volume is empty or its sample count does not match its dimensions");
    validateGeometry(v);
    // The loaders' NaN policy at the library boundary: an in-memory volume with
    // NaN/Inf samples is refused, not rendered differently by each renderer.
    // The values are scanned, whatever the storage (a scale can overflow float).
    // Serial: validation runs before the Scene's thread arena exists (threads = 1 means one).
    std::size_t bad = 0;
    const std::size_t count = v.voxelCount();
    for (std::size_t q = 0; q < count; ++q) bad += !std::isfinite(v.value(q));
    if (bad > 0)
        throw Error("volume has " + std::to_string(bad) +
                    " NaN/Inf samples; replace them (the loaders' --nan-policy zero does)");
    if (!std::isfinite(v.background)) throw Error("volume background value is NaN or Inf");
    s.transfer.validate("transfer function");
    validateFrame(s);
    if (!(s.quality.polynomialTolerance >= 0)) throw Error("polynomial tolerance must be >= 0");
}

bool sameTransfer(const TransferFunction& a, const TransferFunction& b) {
    if (a.points.size() != b.points.size() || a.unitDistance != b.unitDistance ||
        a.normalized != b.normalized)
        return false;
    for (std::size_t n = 0; n < a.points.size(); ++n)
        if (a.points[n].value != b.points[n].value || a.points[n].rgba != b.points[n].rgba)
            return false;
    return true;
}

bool sameClipping(const Clipping& a, const Clipping& b) {
    if (a.planes.size() != b.planes.size() || a.cropBox != b.cropBox) return false;
    if (a.cropBox && (a.boxMin != b.boxMin || a.boxMax != b.boxMax)) return false;
    for (std::size_t n = 0; n < a.planes.size(); ++n)
        if (a.planes[n].point != b.planes[n].point || a.planes[n].normal != b.planes[n].normal)
            return false;
    return true;
}

/// The one rule for what a frame may change: the settings that belong to a Scene
/// (its classification and tables) are fixed at construction; a frame that differs in one of
/// them is refused with the field's name, never silently rendered with the Scene's value.
/// Returns the first such field of `frame` that differs from both the settings the Scene was
/// given and the ones it resolved (a frame may pass either), or "" when none does.
std::string changedSceneField(const RenderSettings& frame, const RenderSettings& given,
                              const RenderSettings& resolved) {
    auto differs = [&](auto get) {
        return !(get(frame) == get(given)) && !(get(frame) == get(resolved));
    };
    if (differs([](const RenderSettings& s) { return s.mode; })) return "mode";
    if (differs([](const RenderSettings& s) { return s.classification; })) return "classification";
    if (differs([](const RenderSettings& s) { return s.kernel; })) return "kernel";
    if (differs([](const RenderSettings& s) { return s.kernelSigma; })) return "kernelSigma";
    if (differs([](const RenderSettings& s) { return s.kernelRadius; })) return "kernelRadius";
    if (!sameTransfer(frame.transfer, given.transfer) &&
        !sameTransfer(frame.transfer, resolved.transfer))
        return "transfer";
    const auto shading = [](const RenderSettings& s) {
        const Shading& h = s.shading;
        return std::make_tuple(h.enabled, h.ambient, h.diffuse, h.specular, h.shininess,
                               h.headlight, h.light);
    };
    if (differs(shading)) return "shading";
    if (differs(
            [](const RenderSettings& s) { return std::make_pair(s.edges.gain, s.edges.exponent); }))
        return "edges";
    if (!sameClipping(frame.clipping, given.clipping)) return "clipping";
    const auto labels = [](const RenderSettings& s) {
        const Labels& l = s.labels;
        return std::make_tuple(l.enabled, l.volume.get(), l.table, l.selection);
    };
    if (differs(labels)) return "labels";
    const auto tables = [](const RenderSettings& s) {
        const Quality& q = s.quality;
        return std::make_tuple(q.footprintResolution, q.slabRadialResolution, q.slabDepthResolution,
                               q.polynomialTolerance);
    };
    if (differs(tables)) return "quality (footprint/slab table resolutions, polynomial tolerance)";
    return "";
}

}  // namespace

void runOnThreads(int threads, const std::function<void()>& f) {
    if (threads > 0) {
        tbb::task_arena arena(threads);
        arena.execute(f);
    } else {
        f();
    }
}

void validateFrame(const RenderSettings& s) {
    const Quality& q = s.quality;
    if (!(q.slab > 0) || !std::isfinite(q.slab) || q.slab > 1e4)
        throw Error("slab thickness must be a positive number of voxels (got " +
                    std::to_string(q.slab) + ")");
    if (s.renderer == RendererKind::Sheet && q.slab < 1e-3)
        throw Error("slab thickness below 0.001 voxels would need millions of sheets");
    if (!(q.earlyTermination >= 0 && q.earlyTermination < 1))
        throw Error("early termination threshold must be in [0, 1)");
    if (q.tileSize < 8 || q.tileSize > 32) throw Error("tile size must be between 8 and 32 pixels");
    if (!(q.warpTolerance >= 0 && q.warpTolerance <= 1))
        throw Error("warp tolerance must be in [0, 1] (0: off)");
    if (!(q.lod.pixels >= 0 && q.lod.pixels <= 64))
        throw Error("level of detail threshold must be between 0 (off) and 64 pixels per voxel");
    if (!(q.pixelFilter >= 0 && q.pixelFilter <= 4))
        throw Error("pixel filter sigma must be between 0 (point sampling) and 4 pixels");
    if (!(q.pixelFilterTolerance > 0) || !std::isfinite(q.pixelFilterTolerance))
        throw Error("pixel filter tolerance must be a positive number");
    if (s.threads < 0 || s.threads > 1024)
        throw Error("thread count must be between 0 (all) and 1024");
    if (!(q.referenceStep >= 0) || !(q.referenceTolerance > 0))
        throw Error("reference step must be >= 0 (0: automatic) and tolerance positive");
    for (int c = 0; c < 4; ++c)
        if (!(s.background[c] >= 0 && s.background[c] <= 1))
            throw Error("background must be in [0, 1]");
}

Scene::Impl::Impl(std::shared_ptr<const Volume> v, const RenderSettings& s)
    : volume(std::move(v)),
      settings(s),
      kernel(makeKernel(s)),
      table(makeTable(kernel, s.quality)) {
    const VolumeStats st = volumeStats(*volume, 1);
    settings.transfer = s.transfer.resolved(st.minValue, st.maxValue);
    minValue = st.minValue;
    maxValue = st.maxValue;
    if (settings.isoNormalized) {
        settings.isoLevel = minValue + settings.isoLevel * (maxValue - minValue);
        settings.isoNormalized = false;
    }
    ClassifyOptions options;
    options.normals = shaded();
    options.gradients = needsGradients();
    if (s.mode == RenderMode::Dvr) options.edges = s.edges;
    options.clipping = s.clipping;
    // The axis-aligned sheets hold whole kernels: every voxel a kept sheet pixel sees
    // (model/clip_region.h); the image-aligned slabs and the reference cut the field along
    // the ray, where a kernel farther than R from the region adds nothing kept.
    if (s.renderer == RendererKind::Axis) options.clipMargin = clipReach(kernel.radius());
    options.compactEmission = true;
    if (s.labels.enabled) {
        if (s.mode != RenderMode::Dvr || s.classification != Classification::Pre)
            throw Error(
                "labels are rendered in dvr mode with pre-classified intensity "
                "(--mode dvr --classify pre)");
        options.labels = &settings.labels;
        labelGrid = shownLabels(*volume, settings.labels);
        labelTable.resize(settings.labels.table.size());
        for (std::size_t n = 0; n < labelTable.size(); ++n) {
            const glm::vec4 c = settings.labels.shown(int(n));
            labelTable[n] = glm::vec4(glm::vec3(c), settings.transfer.extinctionFromOpacity(c.a));
        }
    }
    splats =
        classify(*volume, settings.transfer, s.mode, s.classification, kernel.radius(), options);
    transfer = TransferTable(settings.transfer, 4096, volume->background);
    if (s.quality.polynomialTolerance > 0) {
        poly.emplace(makePoly(table, kernel, s.quality));
        if (poly->maxError() > s.quality.polynomialTolerance) poly.reset();
    }
}

Scene::Impl::Impl(const Impl& fine, Coarser)
    : volume(std::make_shared<const Volume>(coarserGrid(*fine.volume))),
      settings(fine.settings),
      kernel(fine.kernel),
      splats(coarserSplats(fine.splats, fine.volume->dims)),
      transfer(fine.transfer),
      table(fine.table),
      poly(fine.poly),
      level(fine.level + 1),
      minValue(fine.minValue),
      maxValue(fine.maxValue),
      labelTable(fine.labelTable) {}

const Scene::Impl* Scene::Impl::coarser() const {
    if (volume->dims == glm::ivec3(1)) return nullptr;
    std::lock_guard<std::mutex> lock(lazyMutex_);
    // Isolated: while this thread waits inside the merge's parallel loop it must not pick up
    // another frame's task that would ask for this lock again.
    if (!coarser_)
        tbb::this_task_arena::isolate([&] { coarser_ = std::make_unique<Impl>(*this, Coarser{}); });
    return coarser_.get();
}

Scene::Scene(std::shared_ptr<const Volume> volume, const RenderSettings& settings) {
    if (!volume) throw Error("scene: no volume");
    validateScene(*volume, settings);
    runOnThreads(settings.threads,
                 [&] { impl_ = std::make_unique<Impl>(std::move(volume), settings); });
    impl_->given = settings;
}

namespace {
// A borrowed volume is copied (its metadata only: the copy shares the caller's samples and
// holds the keepAlive); an owned one is referenced, and must outlive the Scene.
std::shared_ptr<const Volume> sceneVolume(const Volume& volume) {
    if (volume.borrowed() || volume.data.empty()) return std::make_shared<const Volume>(volume);
    return std::shared_ptr<const Volume>(&volume, [](const Volume*) {});
}
}  // namespace

Scene::Scene(const Volume& volume, const RenderSettings& settings)
    : Scene(sceneVolume(volume), settings) {}

Scene::Scene(Volume&& volume, const RenderSettings& settings)
    : Scene(std::make_shared<const Volume>(std::move(volume)), settings) {}

Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

const Volume& Scene::volume() const { return *impl_->volume; }
const RenderSettings& Scene::settings() const { return impl_->settings; }
const SplatList& Scene::splats() const { return impl_->splats; }
const footprint::Kernel& Scene::kernel() const { return impl_->kernel; }

RenderSettings Scene::frameSettings(const RenderSettings& frame) const {
    const std::string field = changedSceneField(frame, impl_->given, impl_->settings);
    if (!field.empty())
        throw Error("scene: a frame cannot change RenderSettings::" + field +
                    " (the Scene classified with it); build a new Scene for that");
    RenderSettings s = frame;
    s.transfer = impl_->settings.transfer;
    s.shading = impl_->settings.shading;
    s.edges = impl_->settings.edges;
    s.clipping = impl_->settings.clipping;
    s.labels = impl_->settings.labels;
    if (s.isoNormalized) {
        s.isoLevel = impl_->minValue + s.isoLevel * (impl_->maxValue - impl_->minValue);
        s.isoNormalized = false;
    }
    return s;
}

}  // namespace splat
