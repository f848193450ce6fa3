// Pipeline stage "bin to tiles" (see tile_binning.h).
#include "tile_binning.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace splat {

namespace {
// A fixed number of chunks (not one per thread) keeps the result identical for any
// thread count.
constexpr std::size_t kChunks = 64;
/// The rectangles are read in visiting order, scattered in memory: each is requested this
/// many splats ahead of its use.
constexpr std::size_t kAhead = 16;

/// Calls f(t) for every tile t the (non-empty, so inside the image) rectangle r touches.
template <class F>
void forTilesOf(const PixelRect& r, const TileGrid& g, F&& f) {
    const int tx0 = g.tileOf(r.x0), tx1 = g.tileOf(r.x1);
    const int ty0 = g.tileOf(r.y0), ty1 = g.tileOf(r.y1);
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) f(ty * g.tilesX + tx);
}
}  // namespace

void binToTiles(const ProjectedSplats& p, const std::vector<std::uint32_t>& order,
                const std::vector<std::uint32_t>& key, const std::vector<std::uint32_t>& span,
                const TileGrid& grid, TileBins& bins) {
    bins.grid = grid;
    const std::size_t tiles = std::size_t(grid.count());
    const std::size_t n = order.size();
    const std::size_t chunk = (n + kChunks - 1) / kChunks;
    std::vector<std::uint32_t>& counts = bins.counts;
    counts.assign(kChunks * tiles, 0);

    tbb::parallel_for(std::size_t(0), kChunks, [&](std::size_t c) {
        std::uint32_t* cnt = &counts[c * tiles];
        const std::size_t e = std::min(n, (c + 1) * chunk);
        for (std::size_t o = c * chunk; o < e; ++o) {
            if (o + kAhead < e) __builtin_prefetch(&p.rect[order[o + kAhead]]);
            const PixelRect& r = p.rect[order[o]];
            if (!r.empty()) forTilesOf(r, grid, [&](int t) { ++cnt[t]; });
        }
    });
    // Exclusive prefix sum, tile-major then chunk, so each tile's list keeps `order`.
    bins.begin.assign(tiles + 1, 0);
    std::uint64_t total = 0;
    for (std::size_t t = 0; t < tiles; ++t) {
        bins.begin[t] = std::uint32_t(total);
        for (std::size_t c = 0; c < kChunks; ++c) {
            const std::uint32_t k = counts[c * tiles + t];
            counts[c * tiles + t] = std::uint32_t(total);
            total += k;
        }
    }
    bins.begin[tiles] = std::uint32_t(total);
    bins.records.resize(total);
    tbb::parallel_for(std::size_t(0), kChunks, [&](std::size_t c) {
        std::uint32_t* next = &counts[c * tiles];
        const std::size_t e = std::min(n, (c + 1) * chunk);
        for (std::size_t o = c * chunk; o < e; ++o) {
            if (o + kAhead < e) {
                const std::uint32_t a = order[o + kAhead];
                __builtin_prefetch(&p.rect[a]);
                __builtin_prefetch(&p.sx[a]);
                __builtin_prefetch(&p.sy[a]);
                __builtin_prefetch(&p.depth[a]);
                __builtin_prefetch(&key[a]);
                __builtin_prefetch(&span[a]);
            }
            const std::uint32_t id = order[o];
            const PixelRect& r = p.rect[id];
            if (r.empty()) continue;
            const SheetRecord rec{id, key[id], span[id], p.sx[id], p.sy[id], p.depth[id]};
            forTilesOf(r, grid, [&](int t) { bins.records[next[t]++] = rec; });
        }
    });
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

}  // namespace splat
