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
          tilesY((h + tile - 1) / tile) {}
    int count() const { return tilesX * tilesY; }
};

/// The part of a rectangle inside tile `t`.
inline PixelRect clipToTile(PixelRect r, const TileGrid& g, int t) {
    const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
    r.x0 = std::max(r.x0, ox);
    r.y0 = std::max(r.y0, oy);
    r.x1 = std::min(r.x1, std::min(ox + g.tileSize, g.width) - 1);
    r.y1 = std::min(r.y1, std::min(oy + g.tileSize, g.height) - 1);
    return r;
}

struct TileBins {
    TileGrid grid;
    std::vector<std::uint32_t> begin;   ///< grid.count() + 1 offsets
    std::vector<std::uint32_t> splats;  ///< splat indices, per tile in `order`
    std::vector<std::uint32_t> counts;  ///< scratch: per chunk and tile
};

/// Bins the splats listed in `order` (visiting order) to tiles, into `bins` (its arrays
/// are reused across frames).
void binToTiles(const ProjectedSplats& p, const std::vector<std::uint32_t>& order,
                const TileGrid& grid, TileBins& bins);

}  // namespace splat
