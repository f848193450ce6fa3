// Stages "project" and "bin" of a streaming splatter, chunk by chunk (see chunk_binning.h).
#include "frame/chunk_binning.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace splat {

namespace {
// A fixed number of parts (not one per thread) keeps the lists identical for any thread count.
constexpr std::size_t kParts = 32;
// A splat records whether it is visible in each of the first kMaskTiles tiles of its box;
// boxes over more tiles (huge footprints) are binned to all of them unculled.
constexpr int kMaskTiles = 16;
// Runs (pass 1) and positions (pass 2) ahead whose splat data binning prefetches.
constexpr std::size_t kAhead = 8, kAheadPositions = 32;

/// Calls f(tx, ty, k) for the tiles the box touches, k counting them from 0 (row-major).
template <class F>
void forTilesOf(const PixelRect& r, const TileGrid& g, F&& f) {
    const int tx0 = g.tileOf(r.x0), tx1 = g.tileOf(r.x1);
    const int ty0 = g.tileOf(r.y0), ty1 = g.tileOf(r.y1);
    int k = 0;
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) f(tx, ty, k++);
}
}  // namespace

Occlusion::Occlusion(const TileGrid& grid, const std::vector<TileAccumulator>& tiles, bool cull)
    : g_(grid),
      cull_(cull),
      mask_(std::size_t(grid.count()), 0),
      blocksX_(std::size_t(grid.count()), 0) {
    if (!cull) return;
    tbb::parallel_for(0, g_.count(), [&](int t) {
        const TileAccumulator& acc = tiles[std::size_t(t)];
        const int bx = (acc.width() + kBlock - 1) / kBlock,
                  by = (acc.height() + kBlock - 1) / kBlock;
        blocksX_[std::size_t(t)] = bx;
        std::uint64_t m = 0;
        for (int y = 0; y < by; ++y)
            for (int x = 0; x < bx; ++x)
                if (acc.rectOpaque(x * kBlock, y * kBlock, x * kBlock, y * kBlock))
                    m |= std::uint64_t(1) << (y * bx + x);
        mask_[std::size_t(t)] = m;
    });
}

bool Occlusion::visible(const PixelRect& r) const {
    if (!cull_) return true;
    const int tx0 = g_.tileOf(r.x0), tx1 = g_.tileOf(r.x1);
    const int ty0 = g_.tileOf(r.y0), ty1 = g_.tileOf(r.y1);
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx)
            if (visible(r, tx, ty)) return true;
    return false;
}

std::size_t binChunk(const SplatProjector& projector, const VisitOrder& order,
                     const std::vector<std::uint32_t>& runs, const TileGrid& grid,
                     const Occlusion& occlusion, const SplatRecordFields& fields, ChunkBins& out) {
    const bool cull = occlusion.enabled();
    const std::size_t n = runs.empty() ? 0 : runs.back(), tileCount = std::size_t(grid.count());
    const std::size_t runCount = runs.empty() ? 0 : runs.size() - 1;
    const std::size_t runsPerPart = (runCount + kParts - 1) / kParts;
    // Part c: runs [c runsPerPart, (c + 1) runsPerPart), positions partStart(c) ..
    auto partStart = [&](std::size_t c) { return runs[std::min(runCount, c * runsPerPart)]; };
    out.sx.resize(n);
    out.sy.resize(n);
    out.rect.resize(n);
    out.visible.resize(n);
    if (projector.perspective()) out.each.resize(n);
    out.counts.assign(kParts * tileCount, 0);
    std::vector<std::size_t> hidden(kParts, 0);
    const bool ortho = !projector.perspective(), runBoxes = cull && ortho;
    // Pass 1: project, and count the tiles where each splat is visible. A run (splats of one
    // row, between its first and last) whose box is hidden everywhere is skipped whole.
    tbb::parallel_for(std::size_t(0), kParts, [&](std::size_t c) {
        std::uint32_t* cnt = &out.counts[c * tileCount];
        const std::size_t re = std::min(runCount, (c + 1) * runsPerPart);
        std::size_t h = 0;
        for (std::size_t run = std::min(runCount, c * runsPerPart); run < re; ++run) {
            const std::size_t a = runs[run], b = runs[run + 1];
            if (run + kAhead < re) projector.prefetch(order[runs[run + kAhead]]);
            // Orthographic: the run's positions are affine along its row.
            const SplatProjector::Row row =
                ortho ? projector.row(order[a]) : SplatProjector::Row{0, 0, 0, 0};
            if (runBoxes && b - a >= 2) {
                float xa, ya, xb, yb;
                projector.project(row, order[a], xa, ya);
                projector.project(row, order[b - 1], xb, yb);
                // Every centre of the run lies between the two ends: one box (widened by a
                // pixel against rounding) holds all their footprint boxes.
                footprint::EllipticalFootprint e = projector.shared();
                e.halfWidth += 0.5f * std::abs(xa - xb) + 1.0f;
                e.halfHeight += 0.5f * std::abs(ya - yb) + 1.0f;
                const PixelRect box =
                    footprintRect(0.5f * (xa + xb), 0.5f * (ya + yb), e, grid.width, grid.height);
                bool any = box.empty();
                if (!box.empty())
                    forTilesOf(box, grid, [&](int tx, int ty, int k) {
                        any |= k >= kMaskTiles || occlusion.visible(box, tx, ty);
                    });
                if (!any) {
                    for (std::size_t q = a; q < b; ++q) out.visible[q] = 0;
                    h += b - a;
                    continue;
                }
            }
            for (std::size_t q = a; q < b; ++q) {
                const PixelRect r =
                    ortho ? projector.project(row, order[q], out.sx[q], out.sy[q])
                          : projector.project(order[q], out.sx[q], out.sy[q], &out.each[q]);
                out.rect[q] = r;
                std::uint32_t bits = 0;
                if (!r.empty())
                    forTilesOf(r, grid, [&](int tx, int ty, int k) {
                        const bool v = k >= kMaskTiles || occlusion.visible(r, tx, ty);
                        cnt[ty * grid.tilesX + tx] += v;
                        bits |= std::uint32_t(v) << std::min(k, kMaskTiles);
                    });
                out.visible[q] = bits;
                h += bits == 0 && !r.empty();
            }
        }
        hidden[c] = h;
    });
    // Exclusive prefix sum, tile-major then part, so each tile's list keeps the order.
    out.begin.assign(tileCount + 1, 0);
    std::size_t total = 0;
    for (std::size_t t = 0; t < tileCount; ++t) {
        out.begin[t] = std::uint32_t(total);
        for (std::size_t c = 0; c < kParts; ++c) {
            const std::uint32_t k = out.counts[c * tileCount + t];
            out.counts[c * tileCount + t] = std::uint32_t(total);
            total += k;
        }
    }
    out.begin[tileCount] = std::uint32_t(total);
    out.records.resize(total);
    // Pass 2: the records.
    tbb::parallel_for(std::size_t(0), kParts, [&](std::size_t c) {
        std::uint32_t* next = &out.counts[c * tileCount];
        const std::size_t e = partStart(c + 1);
        for (std::size_t q = partStart(c); q < e; ++q) {
            if (q + kAheadPositions < e) {
                const std::uint32_t ahead = order[q + kAheadPositions];
                if (fields.slice) __builtin_prefetch(&fields.slice[ahead]);
                if (fields.value) __builtin_prefetch(&fields.value[ahead]);
            }
            const std::uint32_t bits = out.visible[q];
            if (bits == 0) continue;
            const std::uint32_t id = order[q];
            const SplatRecord rec{id, std::uint32_t(q), out.sx[q], out.sy[q],
                                  fields.slice ? fields.slice[id] : std::uint16_t(0),
                                  fields.value ? fields.value[id] : std::uint16_t(0)};
            forTilesOf(out.rect[q], grid, [&](int tx, int ty, int k) {
                if (bits >> std::min(k, kMaskTiles) & 1)
                    out.records[next[ty * grid.tilesX + tx]++] = rec;
            });
        }
    });
    std::size_t culled = 0;
    for (std::size_t h : hidden) culled += h;
    return culled;
}

}  // namespace splat
