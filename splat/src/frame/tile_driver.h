#pragma once
// Pipeline stage "tiles", shared by both splatters: every screen tile, in parallel, owns
// its ring of sheet buffers and its compositing state (so threads never share a pixel and
// the image does not depend on the thread count) and sweeps its splats in visiting order:
//
//   for each splat: clip to the tile -> occlusion test -> footprint ellipse and values
//                   -> the splatter's Cutter adds the kernel to the sheets it spans
//   when the sweep passes a sheet: flush it through the compositing policy (sheet -> sample
//                   -> accumulate); stop when the whole tile is opaque
//   then: resolve the tile into the image.
//
// A Cutter says which sheet a splat starts in (key, in visiting order), how many sheets it
// spans, and how its kernel is cut into them, each from the splat's record in the tile's
// list (the Source's: SheetRecord, or a SplatRecord per splat of a chunk's RunRecord, which
// lists a run of splats in one sheet as one entry); that is all that differs between the
// axis-aligned (one sheet: the whole footprint) and the image-aligned splatter (every slab
// it crosses: slab sections).
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include "frame/chunk_binning.h"
#include "frame/compositing.h"
#include "frame/frame_progress.h"
#include "frame/projection.h"
#include "frame/sheet_buffer.h"
#include "frame/tile_binning.h"
#include "model/scene_impl.h"
#include "splat/camera.h"

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace splat {

/// How a view cuts the kernels into sheets: what the order stage decided.
struct SheetPlan {
    std::uint32_t sheets = 0;  ///< sheets of the view, in visiting order
    std::uint32_t ring = 1;    ///< sheet buffers a tile keeps: most sheets one splat spans + 1
    float pathLength = 1;      ///< world length of a ray's path through one sheet
    glm::dvec3 normal{0.0, 0.0, 1.0};  ///< sheet normal, for perspective path lengths
    /// Axis-aligned: the volume axis the sheets are perpendicular to, the ray direction's
    /// sign along it, and whether the visiting order runs up the slice index.
    int axis = -1, sign = 0;
    bool ascending = true;
    /// Image-aligned: depth of the first slab boundary and the slab thickness (world).
    float depthOrigin = 0, thickness = 1;
};

/// What the tile stage reads.
struct TileInputs {
    const Scene::Impl& scene;
    const Camera& camera;
    const RenderSettings& settings;
    const ProjectedSplats& proj;
    const TileBins& bins;
    const SheetPlan& plan;
    const float *er, *eg, *eb;      ///< this view's shaded emission; null: the list's own
    const PolicyContext& policy;    ///< the frame's compositing policy and its parameters
    Image* isoPositions = nullptr;  ///< iso: per pixel, the hit's fractional sheet position
    /// Streaming splatters (rasterizeChunks): one flag per tile of the frame's grid, the
    /// tiles to render (null: all); the others are left empty.
    const std::vector<std::uint8_t>* tiles = nullptr;
};

/// Most sheets one splat may span (the image-aligned splatter's limit) plus one.
inline constexpr std::uint32_t kMaxRing = 8194;

/// Per-tile counters, summed into RenderStats.
struct TileCounters {
    std::size_t footprintPixels = 0, sheets = 0, culled = 0;
};

/// Flushes denormal floats to zero in this thread while in scope. Kernel tails multiply
/// tiny weights; denormal arithmetic is ~100x slower on x86 and changes no visible value.
class DenormalsAreZero {
  public:
#if defined(__SSE__)
    DenormalsAreZero() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040); }
    ~DenormalsAreZero() { _mm_setcsr(saved_); }

  private:
    unsigned saved_;
#endif
};

/// The values a splat contributes to a sheet, in the channels of the policy's source.
template <class Policy>
inline void splatValues(const TileInputs& in, std::uint32_t id, float (&v)[Policy::kChannels]) {
    const SplatList& s = in.scene.splats;
    if constexpr (Policy::kSource == SheetSource::Emission ||
                  Policy::kSource == SheetSource::Labels) {
        const glm::vec4 e = s.emission(id);
        v[0] = e.x;
        v[1] = in.er ? in.er[id] : e.y;
        v[2] = in.er ? in.eg[id] : e.z;
        v[3] = in.er ? in.eb[id] : e.w;
    }
    if constexpr (Policy::kSource == SheetSource::Labels) {
        v[4] = 1.0f;  // every splat competes for the pixel's label, the background too
        v[5] = s.label[id];
    } else if constexpr (Policy::kSource == SheetSource::DensityGradient) {
        v[0] = s.densityOf(id);
        v[1] = s.gx[id];
        v[2] = s.gy[id];
        v[3] = s.gz[id];
    } else if constexpr (Policy::kSource == SheetSource::Density) {
        v[0] = s.densityOf(id);
    }
}

/// splatValues for a tile's record: a chunk's records carry the palette index, read there
/// instead of from the splat list by id.
template <class Policy, class Record>
inline void recordValues(const TileInputs& in, const Record& rec, float (&v)[Policy::kChannels]) {
    if constexpr (std::is_same_v<Record, SplatRecord>) {
        const SplatList& s = in.scene.splats;
        if constexpr (Policy::kSource == SheetSource::Emission) {
            if (s.paletted() && !in.er) {
                const glm::vec4& e = s.palette[rec.value];
                v[0] = e.x;
                v[1] = e.y;
                v[2] = e.z;
                v[3] = e.w;
                return;
            }
        } else if constexpr (Policy::kSource == SheetSource::Density) {
            if (s.paletted()) {
                v[0] = s.paletteDensity[rec.value];
                return;
            }
        }
    }
    splatValues<Policy>(in, rec.id, v);
}

/// A tile's records as the whole-frame stages made them (projectSplats, binToTiles).
struct BinnedSplats {
    const TileInputs& in;
    int t;
    std::uint32_t begin() const { return in.bins.begin[t]; }
    std::uint32_t end() const { return in.bins.begin[t + 1]; }
    const SheetRecord& record(std::uint32_t q) const { return in.bins.records[q]; }
    template <class F>
    void forEachSplat(const SheetRecord& r, F&& f) const {
        f(r);
    }
    const footprint::EllipticalFootprint& ellipse(const SheetRecord& r) const {
        return in.proj.ellipse(r.id);
    }
    /// ProjectedSplats::rect of the (binned, so not behind the eye) splat, from its record.
    PixelRect rect(const SheetRecord& r) const {
        return footprintRect(r.sx, r.sy, ellipse(r), in.bins.grid.width, in.bins.grid.height);
    }
};

/// A tile's records of one chunk (chunk_binning.h): runs of splats in one sheet.
struct ChunkRecords {
    const ChunkBins& bins;
    const SplatProjector& projector;
    const TileGrid& grid;
    const VisitOrder& order;
    const SplatRecordFields& fields;
    int t;
    std::uint32_t begin() const { return bins.begin[t]; }
    std::uint32_t end() const { return bins.begin[t + 1]; }
    const RunRecord& record(std::uint32_t q) const { return bins.records[q]; }
    /// Calls f(SplatRecord) for each splat of the run, in visiting order.
    template <class F>
    void forEachSplat(const RunRecord& r, F&& f) const {
        for (std::uint32_t q = r.local, e = r.local + r.count; q < e; ++q) {
            const std::uint32_t id = order[q];
            f(SplatRecord{id, q, bins.sx[q], bins.sy[q], r.slice,
                          fields.value ? bins.value[q] : std::uint16_t(0)});
        }
    }
    const footprint::EllipticalFootprint& ellipse(const SplatRecord& r) const {
        return projector.perspective() ? bins.each[r.local] : projector.shared();
    }
    PixelRect rect(const SplatRecord& r) const {
        return footprintRect(r.sx, r.sy, ellipse(r), grid.width, grid.height);
    }
};

/// The sweep of one tile's list `src` (see the file comment) through a ring of `ring`
/// sheet buffers of this tile (clean on entry; every sheet is flushed before return).
template <class Policy, class Cutter, class Source, int NCh = Policy::kChannels>
void sweepTile(const TileInputs& in, const Policy& policy, const Cutter& cutter, const Source& src,
               const TileGrid& grid, int t, TileAccumulator& acc, SheetBuffer<NCh>* const* sheets,
               std::uint32_t ring, const float* tileScale, TileCounters& cnt) {
    const int ox = (t % grid.tilesX) * grid.tileSize;
    const int oy = (t / grid.tilesX) * grid.tileSize;
    SheetBuffer<NCh>* target[kMaxRing];
    std::uint32_t next = src.begin();
    const std::uint32_t end = src.end();
    if (next == end) return;
    // Sweep position (sheet index in visiting order) and the last position that has
    // contributions pending in the ring.
    std::uint32_t step = cutter.key(src.record(next)), pendingEnd = step;
    bool pending = false;
    while (next < end || pending) {
        if (!pending) step = std::max(step, cutter.key(src.record(next)));  // skip empty sheets
        const std::uint32_t slot = step % ring;  // where sheet `step` is in the ring
        for (; next < end && cutter.key(src.record(next)) == step; ++next)
            src.forEachSplat(src.record(next), [&](const auto& rec) {
                const PixelRect r = clipToTile(src.rect(rec), grid, ox, oy);
                if (r.empty()) return;  // a splat of a run that misses this tile
                if (acc.rectOpaque(r.x0 - ox, r.y0 - oy, r.x1 - ox, r.y1 - oy)) {
                    ++cnt.culled;
                    return;
                }
                const std::uint32_t n = cutter.span(rec);
                for (std::uint32_t j = 0, k = slot; j < n; ++j, k = k + 1 == ring ? 0 : k + 1)
                    target[j] = sheets[k];  // sheets[(step + j) % ring]
                float v[NCh];
                recordValues<Policy>(in, rec, v);
                cnt.footprintPixels += cutter.cut(target, rec, v, src.ellipse(rec), r);
                pendingEnd = std::max(pendingEnd, step + n - 1);
                pending = true;
            });
        SheetBuffer<NCh>& sheet = *sheets[slot];
        if (sheet.dirty()) {
            acc.setSheet(step);
            sheet.flush(acc, policy, in.plan.pathLength, tileScale);
            ++cnt.sheets;
        }
        pending = step < pendingEnd;
        ++step;
        if (acc.allOpaque()) {
            cnt.culled += end - next;
            break;
        }
    }
    if (pending)  // stopped early: leave the ring clean for the next use
        for (std::uint32_t k = 0; k < ring; ++k) sheets[k]->discard();
}

/// The tile's part of the perspective path-length scales (empty for orthographic views).
inline std::vector<float> tilePathScale(const std::vector<float>& pathScale, const TileGrid& g,
                                        int t) {
    std::vector<float> tileScale;
    if (pathScale.empty()) return tileScale;
    const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
    const int w = std::min(g.tileSize, g.width - ox), h = std::min(g.tileSize, g.height - oy);
    tileScale.resize(std::size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            tileScale[std::size_t(y) * w + x] = pathScale[std::size_t(oy + y) * g.width + ox + x];
    return tileScale;
}

inline TileAccumulator makeTileAccumulator(const TileInputs& in, const TileGrid& g, int t,
                                           bool terminates, bool surface) {
    const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
    const int w = std::min(g.tileSize, g.width - ox), h = std::min(g.tileSize, g.height - oy);
    TileAccumulator acc(w, h, in.settings.order,
                        terminates ? in.settings.quality.earlyTermination : 0.0, surface);
    acc.setOrigin(ox, oy, g.width);  // the per-pixel clip cut reads pixel positions
    return acc;
}

inline void addCounters(RenderStats* stats, const std::vector<TileCounters>& counters) {
    for (const auto& c : counters) {
        stats->footprintPixels += c.footprintPixels;
        stats->sheets += c.sheets;
        stats->culledSplats += c.culled;
    }
}

/// Runs sweepTile over every tile in parallel and writes the tiles into the (partial)
/// image; the background is applied afterwards by the frame.
template <class Policy, class Cutter>
Image rasterizeTiles(const TileInputs& in, const Policy& policy, const Cutter& cutter,
                     RenderStats* stats) {
    constexpr int NCh = Policy::kChannels;
    const auto start = std::chrono::steady_clock::now();
    const TileGrid& g = in.bins.grid;
    const std::vector<float> pathScale = perspectivePathScale(in.camera, in.plan.normal);
    Image image(g.width, g.height);
    std::vector<TileCounters> counters(std::size_t(g.count()));
    // One ring of clean sheets per worker thread, moved to each tile it sweeps (a sweep
    // leaves its ring clean), instead of a fresh ring allocated and cleared per tile.
    const std::uint32_t ring = in.plan.ring;
    struct Ring {
        std::vector<std::unique_ptr<SheetBuffer<NCh>>> sheets;
        std::vector<SheetBuffer<NCh>*> ptr;
    };
    tbb::enumerable_thread_specific<Ring> rings;
    FrameProgress progress(in.settings.progress, std::size_t(g.count()), "tiles");
    tbb::parallel_for(0, g.count(), 1, [&](int t) {
        if (progress.stopped()) return;
        const DenormalsAreZero ftz;  // footprint tails must not hit slow denormal paths
        const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
        constexpr bool surface = kSurfacePolicy<Policy>;  // also when clipped
        TileAccumulator acc = makeTileAccumulator(in, g, t, Policy::kTerminates, surface);
        if (in.bins.begin[t] != in.bins.begin[t + 1]) {
            Ring& r = rings.local();
            while (r.sheets.size() < ring) {
                r.sheets.push_back(
                    std::make_unique<SheetBuffer<NCh>>(ox, oy, g.tileSize, g.tileSize));
                r.ptr.push_back(r.sheets.back().get());
            }
            for (std::uint32_t k = 0; k < ring; ++k)
                r.sheets[k]->moveTo(ox, oy, acc.width(), acc.height());
            const std::vector<float> tileScale = tilePathScale(pathScale, g, t);
            sweepTile(in, policy, cutter, BinnedSplats{in, t}, g, t, acc, r.ptr.data(), ring,
                      tileScale.empty() ? nullptr : tileScale.data(), counters[t]);
        }
        acc.resolve(image, ox, oy, in.settings.mode);
        if (surface && in.isoPositions) acc.resolvePositions(*in.isoPositions, ox, oy);
        progress.tick();
    });
    progress.finish();
    if (stats) {
        stats->pathScalePixels = pathScale.size();
        stats->tilesMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        addCounters(stats, counters);
    }
    return image;
}

/// Sorts records [first, last) stably by the cutter's sheet key (a counting sort: a chunk
/// spans few sheets).
template <class Cutter, class Record>
void sortBySheet(const Cutter& cutter, Record* first, Record* last, std::vector<Record>& scratch) {
    if (last - first < 2) return;
    std::uint32_t lo = cutter.key(*first), hi = lo;
    bool sorted = true;
    for (Record* r = first + 1; r != last; ++r) {
        const std::uint32_t k = cutter.key(*r);
        sorted &= k >= cutter.key(*(r - 1));
        lo = std::min(lo, k);
        hi = std::max(hi, k);
    }
    if (sorted) return;
    std::vector<std::uint32_t> start(std::size_t(hi - lo) + 2, 0);
    for (Record* r = first; r != last; ++r) ++start[cutter.key(*r) - lo + 1];
    for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
    scratch.resize(std::size_t(last - first));
    for (Record* r = first; r != last; ++r) scratch[start[cutter.key(*r) - lo]++] = *r;
    std::copy(scratch.begin(), scratch.end(), first);
}

/// Stages "project", "bin" and "tiles" chunk by chunk, front to back (chunk_binning.h): the
/// tiles keep their compositing state from chunk to chunk, and a chunk's splats are binned
/// only where that state is not yet opaque.
template <class Policy, class Cutter>
Image rasterizeChunks(const TileInputs& in, const Policy& policy, const Cutter& cutter,
                      const SheetChunks& sc, ChunkBins& bins, RenderStats* stats) {
    constexpr int NCh = Policy::kChannels;
    using Clock = std::chrono::steady_clock;
    auto ms = [](Clock::time_point a, Clock::time_point b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
    };
    const TileGrid g(in.camera.width(), in.camera.height(), in.settings.quality.tileSize);
    const SplatProjector projector(
        in.scene.splats, in.camera, in.scene.volume->spacing, in.scene.kernel.radius(),
        footprintFilter(in.scene.kernel, in.settings.quality, in.settings.mode, in.camera,
                        *in.scene.volume, in.scene.level));
    const std::vector<float> pathScale = perspectivePathScale(in.camera, in.plan.normal);
    constexpr bool surface = kSurfacePolicy<Policy>;
    const bool cull = Policy::kTerminates && in.settings.order == CompositeOrder::FrontToBack &&
                      in.settings.quality.earlyTermination > 0;
    std::vector<TileAccumulator> tiles;
    tiles.reserve(std::size_t(g.count()));
    for (int t = 0; t < g.count(); ++t)
        tiles.push_back(makeTileAccumulator(in, g, t, Policy::kTerminates, surface));
    std::vector<TileCounters> counters(std::size_t(g.count()));
    // One clean sheet per worker thread, moved to the tile it sweeps (a sweep leaves it clean).
    tbb::enumerable_thread_specific<std::unique_ptr<SheetBuffer<NCh>>> scratch;
    double binMs = 0, tilesMs = 0;
    std::size_t hidden = 0;
    tbb::enumerable_thread_specific<std::vector<RunRecord>> sortScratch;
    const SplatList& splats = in.scene.splats;
    const SplatRecordFields fields{cutter.sliceIndex(),
                                   splats.paletted() ? splats.emissionIndex.data() : nullptr};
    FrameProgress progress(in.settings.progress, sc.count, "chunks");
    for (std::size_t c = 0; c < sc.count; ++c) {
        const auto t0 = Clock::now();
        const Occlusion occlusion(g, tiles, cull, in.tiles);
        hidden += sc.gather(c, bins.ids, bins.runs, BrickTest(projector, occlusion));
        const VisitOrder order{&bins.ids, bins.ids.size(), false};
        hidden += binChunk(projector, order, bins.runs, g, occlusion, fields, bins);
        const auto t1 = Clock::now();
        tbb::parallel_for(0, g.count(), 1, [&](int t) {
            if (bins.begin[t] == bins.begin[t + 1] || progress.stopped()) return;
            if (in.tiles && !(*in.tiles)[std::size_t(t)]) return;  // a huge footprint's entry
            const DenormalsAreZero ftz;
            const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
            sortBySheet(cutter, &bins.records[bins.begin[t]], &bins.records[bins.begin[t + 1]],
                        sortScratch.local());
            TileAccumulator& acc = tiles[std::size_t(t)];
            std::unique_ptr<SheetBuffer<NCh>>& sheet = scratch.local();
            if (!sheet) sheet = std::make_unique<SheetBuffer<NCh>>(ox, oy, g.tileSize, g.tileSize);
            sheet->moveTo(ox, oy, acc.width(), acc.height());
            SheetBuffer<NCh>* ring[1] = {sheet.get()};
            const std::vector<float> tileScale = tilePathScale(pathScale, g, t);
            sweepTile(in, policy, cutter, ChunkRecords{bins, projector, g, order, fields, t}, g, t,
                      acc, ring, 1,
                      tileScale.empty() ? nullptr : tileScale.data(), counters[std::size_t(t)]);
        });
        binMs += ms(t0, t1);
        tilesMs += ms(t1, Clock::now());
        progress.tick();
        progress.finish();
    }
    const auto t2 = Clock::now();
    Image image(g.width, g.height);
    tbb::parallel_for(0, g.count(), 1, [&](int t) {
        const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
        tiles[std::size_t(t)].resolve(image, ox, oy, in.settings.mode);
        if (surface && in.isoPositions)
            tiles[std::size_t(t)].resolvePositions(*in.isoPositions, ox, oy);
    });
    if (stats) {
        stats->pathScalePixels = pathScale.size();
        stats->binMs = binMs;  // projection and binning of the chunks
        stats->tilesMs = tilesMs + ms(t2, Clock::now());
        stats->culledSplats += hidden;
        addCounters(stats, counters);
    }
    return image;
}

/// rasterizeTiles with the compositing policy of the frame's mode.
template <class Cutter>
Image rasterizeWithPolicy(const TileInputs& in, const Cutter& cutter, RenderStats* stats) {
    return withPolicy(
        in.policy, [&](const auto& policy) { return rasterizeTiles(in, policy, cutter, stats); });
}

/// rasterizeChunks with the compositing policy of the frame's mode.
template <class Cutter>
Image rasterizeChunksWithPolicy(const TileInputs& in, const Cutter& cutter, const SheetChunks& sc,
                                ChunkBins& bins, RenderStats* stats) {
    return withPolicy(in.policy, [&](const auto& policy) {
        return rasterizeChunks(in, policy, cutter, sc, bins, stats);
    });
}

}  // namespace splat
