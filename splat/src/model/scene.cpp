// splat::Scene (the view-independent state, built once), splat::Renderer and render().
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "frame/frame.h"
#include "model/clip_region.h"
#include "model/level_of_detail.h"
#include "model/scene_impl.h"
#include "reference/field.h"
#include "reference/reference_frame.h"
#include "splat/error.h"
#include "splat/render.h"

namespace splat {

namespace {

footprint::Kernel makeKernel(const RenderSettings& s) {
    try {
        return footprint::Kernel::fromName(s.kernel, s.kernelSigma, s.kernelRadius);
    } catch (const std::invalid_argument& e) {
        throw Error(e.what());
    }
}

footprint::FootprintTable makeTable(const footprint::Kernel& kernel, const Quality& q) {
    try {
        return footprint::FootprintTable(kernel, q.footprintResolution);
    } catch (const std::invalid_argument& e) {
        throw Error(std::string("footprint table: ") + e.what());
    }
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
    // The loaders' NaN policy at the library boundary (issue 24): an in-memory volume with
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

/// The one rule for what a frame may change (issue 24): the settings that belong to a Scene
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

void orderByKey(const std::vector<std::uint32_t>& key, std::uint32_t keys,
                const std::vector<std::uint32_t>* base, std::vector<std::uint32_t>& order) {
    std::vector<std::uint32_t> start(std::size_t(keys) + 1, 0);
    for (std::uint32_t k : key) ++start[std::size_t(k) + 1];
    for (std::size_t k = 0; k < keys; ++k) start[k + 1] += start[k];
    const std::size_t n = key.size();
    order.resize(n);
    for (std::size_t q = 0; q < n; ++q) {
        const std::uint32_t s = base ? (*base)[q] : std::uint32_t(q);
        order[start[key[s]]++] = s;
    }
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
        poly.emplace(table);
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

const Scene::Impl::SliceOrder& Scene::Impl::sliceOrder(int axis) const {
    std::lock_guard<std::mutex> lock(lazyMutex_);
    if (!sliceOrder_[axis]) {
        const std::vector<std::uint16_t>& index =
            axis == 0 ? splats.i : (axis == 1 ? splats.j : splats.k);
        auto o = std::make_unique<SliceOrder>();
        // Counting sort on the 16-bit slice indices (no widened copy of the keys).
        o->start.assign(std::size_t(volume->dims[axis]) + 1, 0);
        for (std::uint16_t q : index) ++o->start[std::size_t(q) + 1];
        for (std::size_t q = 1; q < o->start.size(); ++q) o->start[q] += o->start[q - 1];
        if (axis != 2) {  // axis 2: the list is in (k, j, i) order already
            std::vector<std::uint32_t> next(o->start.begin(), o->start.end() - 1);
            o->order.resize(index.size());
            for (std::size_t n = 0; n < index.size(); ++n)
                o->order[next[index[n]]++] = std::uint32_t(n);
        }
        sliceOrder_[axis] = std::move(o);
    }
    return *sliceOrder_[axis];
}

const std::vector<std::uint32_t>& Scene::Impl::cellStarts() const {
    std::lock_guard<std::mutex> lock(lazyMutex_);
    if (!cellStarts_) {
        const std::size_t cx = std::size_t(cellsX()),
                          rows = std::size_t(volume->dims.y) * volume->dims.z;
        auto start = std::make_unique<std::vector<std::uint32_t>>(rows * cx + 1, 0);
        std::vector<std::uint32_t>& st = *start;
        const std::size_t n = splats.size();
        for (std::size_t q = 0; q < n; ++q) {
            const std::size_t row = std::size_t(splats.k[q]) * volume->dims.y + splats.j[q];
            ++st[row * cx + splats.i[q] / kCellWidth + 1];
        }
        const glm::ivec3 b = bricks();
        auto counts = std::make_unique<std::vector<std::uint32_t>>(std::size_t(b.x) * b.y * b.z, 0);
        for (std::size_t row = 0; row < rows; ++row) {
            const std::size_t j = row % std::size_t(volume->dims.y), k = row / volume->dims.y;
            const std::size_t brickRow = (k / kCellWidth * b.y + j / kCellWidth) * b.x;
            for (std::size_t c = 0; c < cx; ++c) (*counts)[brickRow + c] += st[row * cx + c + 1];
        }
        for (std::size_t c = 1; c < st.size(); ++c) st[c] += st[c - 1];
        cellStarts_ = std::move(start);
        brickCounts_ = std::move(counts);
    }
    return *cellStarts_;
}

const std::vector<std::uint32_t>& Scene::Impl::brickCounts() const {
    cellStarts();
    return *brickCounts_;
}

const footprint::SlabTable& Scene::Impl::slabTable() const {
    std::lock_guard<std::mutex> lock(lazyMutex_);
    if (!slabTable_) {
        try {
            slabTable_ = std::make_unique<footprint::SlabTable>(
                kernel, settings.quality.slabRadialResolution,
                settings.quality.slabDepthResolution);
        } catch (const std::invalid_argument& e) {
            throw Error(std::string("slab table: ") + e.what());
        }
    }
    return *slabTable_;
}

const ReferenceField& Scene::Impl::referenceField() const {
    std::lock_guard<std::mutex> lock(lazyMutex_);
    if (!field_) {
        validateReferenceKernel(kernel);
        if (splats.paletted() && fieldLayout(settings, splats) == FieldLayout::Emission) {
            // The field reads the emission arrays: a full copy (the other layouts expand
            // the densities alone, in ReferenceField).
            SplatList full = splats;
            full.expandEmission();
            field_ = std::make_shared<ReferenceField>(*volume, full, kernel,
                                                      fieldLayout(settings, full));
        } else {
            field_ = std::make_shared<ReferenceField>(*volume, splats, kernel,
                                                      fieldLayout(settings, splats));
        }
    }
    return *field_;
}

std::unique_ptr<FrameWorkspace> Scene::Impl::acquireWorkspace() const {
    std::lock_guard<std::mutex> lock(poolMutex_);
    if (pool_.empty()) return std::make_unique<FrameWorkspace>();
    std::unique_ptr<FrameWorkspace> w = std::move(pool_.back());
    pool_.pop_back();
    return w;
}

void Scene::Impl::releaseWorkspace(std::unique_ptr<FrameWorkspace> w) const {
    std::lock_guard<std::mutex> lock(poolMutex_);
    pool_.push_back(std::move(w));
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

Image Scene::render(const RenderSettings& frame, RenderStats* stats) const {
    return renderFrame(*impl_, frameSettings(frame), stats);
}

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
