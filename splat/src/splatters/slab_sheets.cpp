// Exact bricks for the image-aligned splatter (splat/slab_sheets.h): the frame pipeline of
// splatters/splat_frame.cpp up to the sheets (shade -> project -> order on the whole frame's slab
// grid -> bin), then the tile sweep of one group of slabs at a time into blocks, and the
// compositing of summed blocks through the mode's policy (SheetBuffer::flush), tile by tile.
#include "splat/slab_sheets.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <type_traits>

#include "frame/policy_context.h"
#include "frame/stopwatch.h"
#include "splat/bricks.h"
#include "splat/error.h"
#include "splatters/splatter.h"

namespace splat {

namespace {

int policyChannels(const PolicyContext& ctx) {
    return withPolicy(ctx, [](const auto& p) { return std::decay_t<decltype(p)>::kChannels; });
}

void checkFrame(const Scene::Impl& scene, const RenderSettings& s) {
    validateFrame(s);
    if (s.renderer != RendererKind::Sheet)
        throw Error("exact brick sheets are the image-aligned splatter's (--renderer sheet)");
    if (scene.settings.labels.enabled) throw Error("--bricks: labels are rendered without bricks");
    if (s.clipping.enabled())
        throw Error("exact brick sheets: clipping is not supported; use --brick-composite fast");
}

}  // namespace

struct BrickSheets::Impl {
    const Scene::Impl& scene;
    RenderSettings s;
    Camera camera;
    WorkspaceLease work;
    glm::ivec3 lo, hi;
    std::vector<std::uint8_t> owned;  // per splat
    std::size_t count = 0;
    float nearest = INFINITY, farthest = -INFINITY;
    double shift = 0;  // the whole volume's camera's depth minus this camera's
    SheetPlan plan;
    PolicyContext ctx;
    SlabLayout layout;

    Impl(const Scene::Impl& sc, const RenderSettings& frame, glm::ivec3 l, glm::ivec3 h)
        : scene(sc), s(frame), camera(frame.camera, *sc.volume), work(sc), lo(l), hi(h) {
        if (s.mode == RenderMode::Iso) s.order = CompositeOrder::FrontToBack;  // as renderFrame
    }
};

BrickSheets::BrickSheets(const Scene& scene, const RenderSettings& frame, const glm::ivec3& ownLo,
                         const glm::ivec3& ownHi, const Volume& whole)
    : impl_(std::make_unique<Impl>(scene.impl(), frame, ownLo, ownHi)) {
    Impl& m = *impl_;
    m.shift = glm::dot(m.camera.eye - Camera(frame.camera, whole).eye, m.camera.view);
    checkFrame(m.scene, m.s);
    if (m.camera.perspective())
        throw Error(
            "exact brick sheets: perspective views are not supported yet; use "
            "--brick-composite fast or --projection ortho");
    const SplatList& list = m.scene.splats;
    runOnThreads(m.s.threads, [&] {
        if (m.scene.shaded())
            shadeEmission(list, m.scene.settings.shading, m.camera.view, m.work->r, m.work->g,
                          m.work->b);
        // The same footprints as the one-process frame: EWA's low-pass (Quality::ewa) too.
        projectSplats(list, m.camera, m.scene.volume->spacing, m.scene.kernel.radius(),
                      m.work->proj,
                      footprintFilter(m.scene.kernel, m.s.quality, m.s.mode, m.camera,
                                      *m.scene.volume, m.scene.level));
    });
    m.owned.resize(list.size());
    const ProjectedSplats& proj = m.work->proj;
    for (std::size_t n = 0; n < list.size(); ++n) {
        const glm::ivec3 p(list.i[n], list.j[n], list.k[n]);
        const bool own =
            glm::all(glm::greaterThanEqual(p, m.lo)) && glm::all(glm::lessThan(p, m.hi));
        m.owned[n] = own;
        if (!own) continue;
        ++m.count;
        m.nearest = std::min(m.nearest, proj.depth[n]);
        m.farthest = std::max(m.farthest, proj.depth[n]);
    }
    // As the one-process frame's slab grid: the kernels' depth extremes widened by a kernel.
    if (m.count) {
        m.nearest = float(m.nearest - proj.depthExtent + m.shift);
        m.farthest = float(m.farthest + proj.depthExtent + m.shift);
    }
}

BrickSheets::~BrickSheets() = default;
BrickSheets::BrickSheets(BrickSheets&&) noexcept = default;
float BrickSheets::nearest() const { return impl_->nearest; }
float BrickSheets::farthest() const { return impl_->farthest; }
std::size_t BrickSheets::splats() const { return impl_->count; }

SlabLayout BrickSheets::plan(float nearest, float farthest) {
    Impl& m = *impl_;
    const SlabLayout whole = slabLayout(m.s, *m.scene.volume, nearest, farthest);
    if (!(nearest <= farthest)) nearest = 0.0f;  // no kernel in any brick
    RenderStats stats;
    runOnThreads(m.s.threads, [&] {
        m.plan = orderOnSlabs(m.scene, m.camera, m.s, *m.work, stats, float(nearest - m.shift),
                              double(whole.slabs));
        // Only the kernels it owns: each kernel of the volume is in exactly one brick's lists.
        std::vector<std::uint32_t>& order = m.work->order;
        order.erase(std::remove_if(order.begin(), order.end(),
                                   [&](std::uint32_t id) { return !m.owned[id]; }),
                    order.end());
        binToTiles(m.work->proj, order, m.work->key, m.work->span,
                   TileGrid(m.camera.width(), m.camera.height(), m.s.quality.tileSize),
                   m.work->bins);
    });
    m.ctx = policyContext(m.scene, m.camera, m.s);
    const TileGrid& g = m.work->bins.grid;
    m.layout.width = g.width;
    m.layout.height = g.height;
    m.layout.tileSize = g.tileSize;
    m.layout.tiles = g.count();
    m.layout.channels = policyChannels(m.ctx);
    m.layout.slabs = m.plan.sheets;
    return m.layout;
}

void BrickSheets::add(std::uint32_t first, std::uint32_t count, float* blocks, int* rects) const {
    const Impl& m = *impl_;
    const bool shaded = m.scene.shaded();
    const TileInputs in{m.scene,
                        m.camera,
                        m.s,
                        m.work->proj,
                        m.work->bins,
                        m.plan,
                        shaded ? m.work->r.data() : nullptr,
                        shaded ? m.work->g.data() : nullptr,
                        shaded ? m.work->b.data() : nullptr,
                        m.ctx,
                        nullptr};
    runOnThreads(m.s.threads, [&] { addSlabSheets(in, first, count, blocks, rects); });
}

struct SlabCompositor::Impl {
    const Scene::Impl& scene;
    RenderSettings s;
    Camera camera;
    SlabLayout layout;
    int t0, t1;
    PolicyContext ctx;
    std::vector<TileAccumulator> tiles;
    Impl(const Scene::Impl& sc, const RenderSettings& frame, const SlabLayout& l, int a, int b)
        : scene(sc), s(frame), camera(frame.camera, *sc.volume), layout(l), t0(a), t1(b) {
        if (s.mode == RenderMode::Iso) s.order = CompositeOrder::FrontToBack;  // as renderFrame
    }
};

SlabCompositor::SlabCompositor(const Scene& scene, const RenderSettings& frame,
                               const SlabLayout& layout, int tileBegin, int tileEnd)
    : impl_(std::make_unique<Impl>(scene.impl(), frame, layout, tileBegin, tileEnd)) {
    Impl& m = *impl_;
    checkFrame(m.scene, m.s);
    m.ctx = policyContext(m.scene, m.camera, m.s);
    if (policyChannels(m.ctx) != layout.channels)
        throw Error("exact brick sheets: the bricks' channels differ");
    const TileGrid g(layout.width, layout.height, layout.tileSize);
    const bool surface = m.s.mode == RenderMode::Iso;
    for (int t = tileBegin; t < tileEnd; ++t) {
        const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
        const int w = std::min(g.tileSize, g.width - ox), h = std::min(g.tileSize, g.height - oy);
        m.tiles.emplace_back(w, h, m.s.order, 0.0, surface);
        m.tiles.back().setOrigin(ox, oy, g.width);
    }
}

SlabCompositor::~SlabCompositor() = default;

void SlabCompositor::composite(std::uint32_t first, std::uint32_t count, const float* blocks,
                               const int* rects) {
    Impl& m = *impl_;
    const SlabLayout& L = m.layout;
    const TileGrid g(L.width, L.height, L.tileSize);
    const float pathLength = float(m.s.quality.slab * m.scene.volume->minSpacing());
    const std::size_t block = L.blockFloats(), plane = std::size_t(L.tileSize) * L.tileSize;
    runOnThreads(m.s.threads, [&] {
        withPolicy(m.ctx, [&](const auto& policy) {
            constexpr int NCh = std::decay_t<decltype(policy)>::kChannels;
            tbb::parallel_for(m.t0, m.t1, 1, [&](int t) {
                const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
                TileAccumulator& acc = m.tiles[std::size_t(t - m.t0)];
                SheetBuffer<NCh> sheet(ox, oy, g.tileSize, g.tileSize);
                sheet.moveTo(ox, oy, acc.width(), acc.height());
                for (std::uint32_t k = 0; k < count; ++k) {
                    const std::size_t at = std::size_t(t - m.t0) * count + k;
                    const int* r = rects + 4 * at;
                    if (r[0] == kNoRect) continue;  // no brick wrote it: the sweep skips it too
                    const int x0 = r[0], y0 = r[1], x1 = -r[2], y1 = -r[3];
                    const float* in = blocks + at * block;
                    for (int c = 0; c < NCh; ++c)
                        for (int y = y0; y <= y1; ++y)
                            std::copy(in + c * plane + std::size_t(y) * L.tileSize + x0,
                                      in + c * plane + std::size_t(y) * L.tileSize + x1 + 1,
                                      sheet.row(c, y) + x0);
                    sheet.markDirty(x0, x1, y0, y1);
                    acc.setSheet(first + k);
                    sheet.flush(acc, policy, pathLength, nullptr);
                }
            });
        });
    });
}

Image SlabCompositor::image() const {
    const Impl& m = *impl_;
    const TileGrid g(m.layout.width, m.layout.height, m.layout.tileSize);
    Image image(g.width, g.height);
    for (int t = m.t0; t < m.t1; ++t)
        m.tiles[std::size_t(t - m.t0)].resolve(image, (t % g.tilesX) * g.tileSize,
                                               (t / g.tilesX) * g.tileSize, m.s.mode);
    return image;
}

std::uint32_t slabGroup(const SlabLayout& layout, std::size_t bytes) {
    const std::size_t perSlab = layout.blockFloats() * sizeof(float) * std::size_t(layout.tiles);
    const std::size_t n = perSlab ? bytes / perSlab : 1;
    return std::uint32_t(std::clamp<std::size_t>(n, 1, std::max<std::uint32_t>(layout.slabs, 1)));
}

SlabLayout slabLayout(const RenderSettings& s, const Volume& geometry, float nearest,
                      float farthest) {
    PolicyContext ctx;
    ctx.mode = s.mode;
    ctx.classification = s.classification;
    ctx.gradients = s.mode == RenderMode::Dvr && s.classification == Classification::Post &&
                    (s.shading.enabled || s.edges.enabled());
    SlabLayout L;
    const TileGrid g(s.camera.width, s.camera.height, s.quality.tileSize);
    L.width = g.width;
    L.height = g.height;
    L.tileSize = g.tileSize;
    L.tiles = g.count();
    L.channels = policyChannels(ctx);
    if (!(nearest <= farthest)) nearest = farthest = 0.0f;
    const float thickness = float(s.quality.slab * geometry.minSpacing());
    L.slabs = std::uint32_t(double(std::floor((farthest - nearest) / thickness)) + 1);
    return L;
}

Image renderBrickedSlabs(
    const Volume& geometry, const BrickLayout& layout, const std::vector<int>& mine,
    const std::function<std::shared_ptr<const Scene>(int, const RenderSettings&)>& scene,
    const RenderSettings& frame, BrickGroup& group, BrickStats& st) {
    RenderSettings s = frame;
    if (s.mode == RenderMode::Iso) s.order = CompositeOrder::FrontToBack;  // as renderFrame
    if (s.clipping.enabled())
        throw Error(
            "--bricks with --renderer sheet: clipping needs --brick-composite fast (approximate)");
    if (!s.quality.lod.off())
        throw Error(
            "--bricks with --renderer sheet renders full resolution: leave out --lod or use "
            "--brick-composite fast");
    // Every brick of this process, held at once: a slab group needs them all.
    std::vector<std::shared_ptr<const Scene>> scenes;
    std::vector<RenderSettings> settings;
    std::vector<BrickSheets> sheets;
    std::string error;
    float nearest = INFINITY, farthest = -INFINITY;
    try {
        for (std::size_t i = 0; i < mine.size(); ++i) {
            const Brick& brick = layout.bricks[std::size_t(mine[i])];
            RenderSettings bs = brickSettings(s, geometry, brick, geometry.dims);
            bs.clipping.planes.clear();  // every kernel in one brick: nothing is cut
            scenes.push_back(scene(int(i), bs));
            const auto t = Clock::now();
            sheets.emplace_back(*scenes.back(), bs, brick.lo - brick.loadLo,
                                brick.hi - brick.loadLo, geometry);
            settings.push_back(bs);
            st.splats += sheets.back().splats();
            nearest = std::min(nearest, sheets.back().nearest());
            farthest = std::max(farthest, sheets.back().farthest());
            st.renderMs += msSince(t);
        }
    } catch (const std::exception& e) {
        error = e.what();
    }
    group.agree(error);
    group.range(nearest, farthest);
    const SlabLayout L = slabLayout(s, geometry, nearest, farthest);
    try {
        const auto t = Clock::now();
        for (BrickSheets& sh : sheets) {
            const SlabLayout mineL = sh.plan(nearest, farthest);
            if (mineL.slabs != L.slabs || mineL.channels != L.channels || mineL.tiles != L.tiles)
                throw Error("exact brick sheets: a brick's slab grid differs from the frame's");
        }
        st.renderMs += msSince(t);
    } catch (const std::exception& e) {
        error = e.what();
    }
    group.agree(error);
    // Screen tiles are composited by the processes that hold a brick (they have a Scene).
    const int p = group.size(), holders = std::min<int>(p, int(layout.bricks.size()));
    std::vector<int> tileStart(std::size_t(p) + 1, L.tiles);
    for (int r = 0; r < holders; ++r)
        tileStart[std::size_t(r)] = int(std::int64_t(L.tiles) * r / holders);
    const int me = group.rank();
    std::optional<SlabCompositor> compositor;
    try {
        if (me < holders)
            compositor.emplace(*scenes.front(), settings.front(), L, tileStart[std::size_t(me)],
                               tileStart[std::size_t(me) + 1]);
    } catch (const std::exception& e) {
        error = e.what();
    }
    group.agree(error);
    // One group of slabs of the whole frame in at most 64 MiB.
    const std::uint32_t group0 = slabGroup(L, std::size_t(64) << 20);
    std::vector<float> blocks;
    std::vector<int> rects;
    for (std::uint32_t first = 0; first < L.slabs; first += group0) {
        const std::uint32_t n = std::min(group0, L.slabs - first);
        auto t = Clock::now();
        try {  // (an allocation that fails on one process must not leave the others waiting)
            blocks.assign(std::size_t(L.tiles) * n * L.blockFloats(), 0.0f);
            rects.assign(std::size_t(L.tiles) * n * 4, kNoRect);
            for (const BrickSheets& sh : sheets) sh.add(first, n, blocks.data(), rects.data());
        } catch (const std::exception& e) {
            error = e.what();
        }
        group.agree(error);
        st.renderMs += msSince(t);
        t = Clock::now();
        group.reduceSlabs(blocks, rects, tileStart, n * L.blockFloats(), std::size_t(n) * 4,
                          &st.bytesExchanged);
        if (compositor) compositor->composite(first, n, blocks.data(), rects.data());
        st.compositeMs += msSince(t);
    }
    const auto t = Clock::now();
    Image out = group.sumImages(compositor ? compositor->image() : Image(L.width, L.height),
                                &st.bytesExchanged);
    if (me == 0) applyBackground(out, s.mode, s.background, geometry.background);
    st.compositeMs += msSince(t);
    return out;
}

}  // namespace splat
