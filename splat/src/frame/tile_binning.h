#pragma once
// Pipeline stage "bin to tiles": each splat is listed in every screen tile its footprint's
// bounding box touches, in a given visiting order (compressed rows: tile t owns
// splats[begin[t] .. begin[t + 1])). Tiles then render independently, so threads never
// share a pixel and the image does not depend on the thread count.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "projection.h"

namespace splat {

struct TileGrid {
    int width = 0, height = 0, tileSize = 32, tilesX = 0, tilesY = 0;
    TileGrid() = default;
    TileGrid(int w, int h, int tile)
        : width(w),
          height(h),
          tileSize(tile),
          tilesX((w + tile - 1) / tile),
          tilesY((h + tile - 1) / tile),
          magic_((std::uint64_t(1) << 32) / std::uint64_t(tile) + 1) {}
    int count() const { return tilesX * tilesY; }
    /// Tile column (or row) of pixel column (or row) p >= 0: p / tileSize by a multiply
    /// (exact for p < 2^20, far beyond the largest image), as binning does it per splat.
    int tileOf(int p) const { return int((std::uint64_t(p) * magic_) >> 32); }

  private:
    std::uint64_t magic_ = 0;
};

/// The part of a rectangle inside the tile whose top-left pixel is (ox, oy).
inline PixelRect clipToTile(PixelRect r, const TileGrid& g, int ox, int oy) {
    r.x0 = std::max(r.x0, ox);
    r.y0 = std::max(r.y0, oy);
    r.x1 = std::min(r.x1, std::min(ox + g.tileSize, g.width) - 1);
    r.y1 = std::min(r.y1, std::min(oy + g.tileSize, g.height) - 1);
    return r;
}

/// The part of a rectangle inside tile `t`.
inline PixelRect clipToTile(PixelRect r, const TileGrid& g, int t) {
    return clipToTile(r, g, (t % g.tilesX) * g.tileSize, (t / g.tilesX) * g.tileSize);
}

/// One entry of a tile's list: what the tile sweep reads of a splat, written by binning
/// in visiting order so that the sweep streams through its records instead of reading the
/// per-splat arrays at random by splat index (24 bytes).
struct SheetRecord {
    std::uint32_t id;    ///< splat index
    std::uint32_t key;   ///< first sheet the splat touches, in visiting order
    std::uint32_t span;  ///< sheets it spans from there
    float sx, sy;        ///< screen position of the centre (ProjectedSplats::sx, sy)
    float depth;         ///< depth of the centre (ProjectedSplats::depth)
};

struct TileBins {
    TileGrid grid;
    std::vector<std::uint32_t> begin;   ///< grid.count() + 1 offsets
    std::vector<SheetRecord> records;   ///< per tile, in `order`
    std::vector<std::uint32_t> counts;  ///< scratch: per chunk and tile
};

/// Stage "order" (the visiting order binning follows): a stable counting sort of the
/// elements of `base` (or 0 .. key.size() - 1 when `base` is null) by key[element], keys in
/// [0, keys).
void orderByKey(const std::vector<std::uint32_t>& key, std::uint32_t keys,
                const std::vector<std::uint32_t>* base, std::vector<std::uint32_t>& order);

/// Bins the splats listed in `order` (visiting order) to tiles, into `bins` (its arrays
/// are reused across frames); key[id] and span[id] are splat id's sheets (SheetRecord).
void binToTiles(const ProjectedSplats& p, const std::vector<std::uint32_t>& order,
                const std::vector<std::uint32_t>& key, const std::vector<std::uint32_t>& span,
                const TileGrid& grid, TileBins& bins);

}  // namespace splat
