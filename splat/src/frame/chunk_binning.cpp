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
/// The pixel box holding the footprint boxes (footprintRect) of every centre in
/// [x0, x1] x [y0, y1]: float rounding is monotone, so each of theirs lies inside.
PixelRect footprintRectOfCentres(float x0, float x1, float y0, float y1,
                                 const footprint::EllipticalFootprint& e, int width, int height) {
    const float fx0 = std::ceil(x0 - e.halfWidth - 0.5f), fx1 = std::floor(x1 + e.halfWidth - 0.5f);
    const float fy0 = std::ceil(y0 - e.halfHeight - 0.5f),
                fy1 = std::floor(y1 + e.halfHeight - 0.5f);
    if (!(fx1 >= 0.0f) || !(fy1 >= 0.0f) || !(fx0 <= float(width - 1)) ||
        !(fy0 <= float(height - 1)) || fx0 > fx1 || fy0 > fy1)
        return {1, 1, 0, 0};
    return {int(std::max(fx0, 0.0f)), int(std::max(fy0, 0.0f)),
            int(std::min(fx1, float(width - 1))), int(std::min(fy1, float(height - 1)))};
}
}  // namespace

Occlusion::Occlusion(const TileGrid& grid, const std::vector<TileAccumulator>& tiles, bool cull,
                     const std::vector<std::uint8_t>* only)
    : g_(grid),
      cull_(cull || only),
      mask_(std::size_t(grid.count()), 0),
      blocksX_(std::size_t(grid.count()), 0) {
    if (!cull_) return;
    tbb::parallel_for(0, g_.count(), [&](int t) {
        const TileAccumulator& acc = tiles[std::size_t(t)];
        const int bx = (acc.width() + kBlock - 1) / kBlock,
                  by = (acc.height() + kBlock - 1) / kBlock;
        blocksX_[std::size_t(t)] = bx;
        std::uint64_t m = 0;
        if (only && !(*only)[std::size_t(t)])
            m = bx * by == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << (bx * by)) - 1;
        else if (cull)
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

namespace {

/// One chunk's binning: its inputs, its output and how its runs are cut into kParts parts
/// (a fixed number, so that the lists are identical for any thread count).
struct ChunkBinning {
    const SplatProjector& projector;
    const VisitOrder& order;
    const std::vector<std::uint32_t>& runs;
    const TileGrid& grid;
    const Occlusion& occlusion;
    const SplatRecordFields& fields;
    ChunkBins& out;
    std::size_t n, tileCount, runCount, runsPerPart;

    ChunkBinning(const SplatProjector& p, const VisitOrder& o, const std::vector<std::uint32_t>& r,
                 const TileGrid& g, const Occlusion& occ, const SplatRecordFields& f,
                 ChunkBins& bins)
        : projector(p), order(o), runs(r), grid(g), occlusion(occ), fields(f), out(bins) {
        n = runs.empty() ? 0 : runs.back();
        tileCount = std::size_t(grid.count());
        runCount = runs.empty() ? 0 : runs.size() - 1;
        runsPerPart = (runCount + kParts - 1) / kParts;
    }
    /// Position of run r's first splat (n from runCount on).
    std::size_t runStart(std::size_t r) const { return r < runCount ? std::size_t(runs[r]) : n; }
};

/// Sizes the chunk's arrays for its splats and zeroes the per-part tile counts.
void prepareBins(const ChunkBinning& cb) {
    ChunkBins& out = cb.out;
    const std::size_t n = cb.n;
    out.sx.resize(n);
    out.sy.resize(n);
    if (cb.fields.value) out.value.resize(n);
    out.rect.resize(n);
    out.visible.resize(n);
    out.entry.resize(n);
    if (cb.projector.perspective()) out.each.resize(n);
    out.counts.assign(kParts * cb.tileCount, 0);
}

/// Pass 1 over part c's runs: project, and count the tiles where each entry (a run in one
/// sheet, or a splat; at the entry's first position q: entry[q] splats, box rect[q], tiles
/// visible[q]) is visible. A run whose box is hidden everywhere is skipped whole. Returns
/// the splats hidden in every tile they touch.
std::size_t projectAndCount(const ChunkBinning& cb, std::size_t c) {
    const SplatProjector& projector = cb.projector;
    const VisitOrder& order = cb.order;
    const std::vector<std::uint32_t>& runs = cb.runs;
    const TileGrid& grid = cb.grid;
    const Occlusion& occlusion = cb.occlusion;
    const SplatRecordFields& fields = cb.fields;
    ChunkBins& out = cb.out;
    const std::size_t tileCount = cb.tileCount, runCount = cb.runCount,
                      runsPerPart = cb.runsPerPart;
    const bool ortho = !projector.perspective(), runBoxes = occlusion.enabled() && ortho;
    const footprint::EllipticalFootprint& shared = projector.shared();
    std::uint32_t* cnt = &out.counts[c * tileCount];
    const std::size_t re = std::min(runCount, (c + 1) * runsPerPart);
    std::size_t h = 0;
    // Lists the entry at q (box r) in the tiles where it is visible.
    auto list = [&](std::size_t q, const PixelRect& r) {
        std::uint32_t bits = 0;
        if (!r.empty())
            forTilesOf(r, grid, [&](int tx, int ty, int k) {
                const bool v = k >= kMaskTiles || occlusion.visible(r, tx, ty);
                cnt[ty * grid.tilesX + tx] += v;
                bits |= std::uint32_t(v) << std::min(k, kMaskTiles);
            });
        out.rect[q] = r;
        out.visible[q] = bits;
        return bits != 0 || r.empty();
    };
    for (std::size_t run = std::min(runCount, c * runsPerPart); run < re; ++run) {
        const std::size_t a = runs[run], b = runs[run + 1];
        if (run + kAhead < re) {
            const std::uint32_t ahead = order[runs[run + kAhead]];
            projector.prefetch(ahead);
            if (fields.value) __builtin_prefetch(&fields.value[ahead]);
        }
        const bool oneSheet =
            ortho && b - a <= 0xFFFF &&
            (!fields.slice || fields.slice[order[a]] == fields.slice[order[b - 1]]);
        // Orthographic: positions are affine along a volume row; a run along another
        // line (a column) takes each splat's own row.
        SplatProjector::Row row = ortho ? projector.row(order[a]) : SplatProjector::Row{};
        const bool alongRow = ortho && b - a >= 2 && [&] {
            const SplatProjector::Row last = projector.row(order[b - 1]);
            return last.x0 == row.x0 && last.y0 == row.y0;
        }();
        // The sweep reads a splat's palette entry by chunk position, not by id at random.
        auto copyValue = [&](std::size_t q) {
            if (fields.value) out.value[q] = fields.value[order[q]];
        };
        auto project = [&](std::size_t q) {
            if (!alongRow && b - a >= 2) row = projector.row(order[q]);
            copyValue(q);
            return projector.project(row, order[q], out.sx[q], out.sy[q]);
        };
        // A run in one sheet is tested by its exact box below; another is first tested
        // by the box of its ends, before its inner splats are projected.
        if (runBoxes && b - a >= 2 && !oneSheet) {
            project(a);
            project(b - 1);
            const float xa = out.sx[a], ya = out.sy[a], xb = out.sx[b - 1], yb = out.sy[b - 1];
            // Every centre of the run lies between the two ends: one box (widened by a
            // pixel against rounding) holds all their footprint boxes.
            footprint::EllipticalFootprint e = shared;
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
                out.entry[a] = std::uint32_t(b - a);
                out.visible[a] = 0;
                h += b - a;
                continue;
            }
        }
        if (oneSheet) {
            // One entry: the box of the footprints of every centre of the run.
            float x0 = 1e30f, x1 = -1e30f, y0 = 1e30f, y1 = -1e30f;
            for (std::size_t q = a; q < b; ++q) {
                project(q);
                x0 = std::min(x0, out.sx[q]);
                x1 = std::max(x1, out.sx[q]);
                y0 = std::min(y0, out.sy[q]);
                y1 = std::max(y1, out.sy[q]);
            }
            out.entry[a] = std::uint32_t(b - a);
            if (!list(a, footprintRectOfCentres(x0, x1, y0, y1, shared, grid.width, grid.height)))
                h += b - a;
            continue;
        }
        for (std::size_t q = a; q < b; ++q) {
            const PixelRect r = ortho ? project(q)
                                      : (copyValue(q), projector.project(order[q], out.sx[q],
                                                                         out.sy[q], &out.each[q]));
            out.entry[q] = 1;
            h += !list(q, r);
        }
    }
    return h;
}

/// The exclusive prefix sum of the per-part tile counts, tile-major then part, so that each
/// tile's list keeps the visiting order: out.begin per tile, and in out.counts the position
/// where each part writes its first record of each tile.
void tileOffsets(const ChunkBinning& cb) {
    ChunkBins& out = cb.out;
    const std::size_t tileCount = cb.tileCount;
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
}

/// Pass 2 over part c: the records, entry by entry over the same runs as pass 1.
void writeRecords(const ChunkBinning& cb, std::size_t c) {
    const VisitOrder& order = cb.order;
    const TileGrid& grid = cb.grid;
    const SplatRecordFields& fields = cb.fields;
    ChunkBins& out = cb.out;
    const std::size_t tileCount = cb.tileCount, runsPerPart = cb.runsPerPart;
    std::uint32_t* next = &out.counts[c * tileCount];
    const std::size_t e = cb.runStart((c + 1) * runsPerPart);
    for (std::size_t q = cb.runStart(c * runsPerPart); q < e; q += out.entry[q]) {
        if (q + kAheadPositions < e && fields.slice)
            __builtin_prefetch(&fields.slice[order[q + kAheadPositions]]);
        const std::uint32_t bits = out.visible[q];
        if (bits == 0) continue;
        const RunRecord rec{std::uint32_t(q), std::uint16_t(out.entry[q]),
                            fields.slice ? fields.slice[order[q]] : std::uint16_t(0)};
        forTilesOf(out.rect[q], grid, [&](int tx, int ty, int k) {
            if (bits >> std::min(k, kMaskTiles) & 1)
                out.records[next[ty * grid.tilesX + tx]++] = rec;
        });
    }
}

}  // namespace

std::size_t binChunk(const SplatProjector& projector, const VisitOrder& order,
                     const std::vector<std::uint32_t>& runs, const TileGrid& grid,
                     const Occlusion& occlusion, const SplatRecordFields& fields, ChunkBins& out) {
    const ChunkBinning cb(projector, order, runs, grid, occlusion, fields, out);
    prepareBins(cb);
    std::vector<std::size_t> hidden(kParts, 0);
    tbb::parallel_for(std::size_t(0), kParts,
                      [&](std::size_t c) { hidden[c] = projectAndCount(cb, c); });
    tileOffsets(cb);
    tbb::parallel_for(std::size_t(0), kParts, [&](std::size_t c) { writeRecords(cb, c); });
    std::size_t culled = 0;
    for (std::size_t h : hidden) culled += h;
    return culled;
}

}  // namespace splat
