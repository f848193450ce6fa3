#pragma once
// Pipeline stage "bin to tiles": each splat is listed in every screen tile its footprint's
// bounding box touches, in a given visiting order (compressed rows: tile t owns
// splats[begin[t] .. begin[t + 1])). Tiles then render independently, so threads never
// share a pixel and the image does not depend on the thread count.
#include <cstdint>
#include <vector>

#include "projection.h"

namespace splat {

struct TileGrid {
    int width = 0, height = 0, tileSize = 32, tilesX = 0, tilesY = 0;
    TileGrid() = default;
    TileGrid(int w, int h, int tile)
        : width(w), height(h), tileSize(tile), tilesX((w + tile - 1) / tile),
          tilesY((h + tile - 1) / tile) {}
    int count() const { return tilesX * tilesY; }
};

/// Inclusive pixel range covered by a splat's footprint bounding box, clamped to the
/// image; empty when x0 > x1 or y0 > y1.
struct PixelRect {
    int x0, y0, x1, y1;
    bool empty() const { return x0 > x1 || y0 > y1; }
};
PixelRect footprintPixels(const ProjectedSplats& p, std::size_t s, const TileGrid& grid);

struct TileBins {
    TileGrid grid;
    std::vector<std::uint32_t> begin;   ///< grid.count() + 1 offsets
    std::vector<std::uint32_t> splats;  ///< splat indices, per tile in `order`
};

/// Bins the splats listed in `order` (visiting order) to tiles.
TileBins binToTiles(const ProjectedSplats& p, const std::vector<std::uint32_t>& order,
                    const TileGrid& grid);

}  // namespace splat
