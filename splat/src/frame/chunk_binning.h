#pragma once
// Stages "project" and "bin" of a streaming splatter, one chunk of sheets at a time, with
// early splat elimination (K. Mueller, N. Shareef, J. Huang, R. Crawfis, "High-quality
// splatting on rectilinear grids with efficient culling of occluded voxels", IEEE TVCG
// 1999): the frame's sheets are visited in chunks, front to back; a chunk's splats are
// projected and listed in the tiles their footprint box touches only where the tile's
// compositing state is not yet opaque over the box. A splat hidden in every tile it touches
// costs its projection and nothing else: it is never binned, cut or streamed. Since the
// sweep's own test would skip exactly those splats later (opacity only grows), the image
// is the same as with binning everything, and it does not depend on the thread count.
#include <cstdint>
#include <functional>
#include <vector>

#include "frame/compositing.h"
#include "frame/projection.h"
#include "frame/tile_binning.h"

namespace splat {

/// One entry of a tile's list: the splat, its position in the chunk and its screen centre
/// (written by binning, so that the tile sweep streams through its records).
struct SplatRecord {
    std::uint32_t id, local;
    float sx, sy;
};

/// Splat indices in visiting order: base[o] (base null: o), read from the end when reversed.
struct VisitOrder {
    const std::vector<std::uint32_t>* base = nullptr;
    std::size_t size = 0;
    bool reversed = false;
    std::uint32_t operator[](std::size_t o) const {
        const std::size_t q = reversed ? size - 1 - o : o;
        return base ? (*base)[q] : std::uint32_t(q);
    }
};

/// What a streaming splatter hands the chunked tile stage (tile_driver.h): `count` chunks
/// of whole sheets in visiting order; gather(c, ids, runs) lists chunk c's splats in any
/// order (binning sorts each tile's records by sheet, stably), cut into runs along volume
/// rows (binChunk). Its cutter spans one sheet per
/// splat (a ring of one), so no sheet is pending between chunks.
struct SheetChunks {
    std::size_t count = 0;
    std::function<void(std::size_t, std::vector<std::uint32_t>&, std::vector<std::uint32_t>&)>
        gather;
};

/// One chunk's splats binned to tiles (arrays reused from chunk to chunk and frame to frame).
struct ChunkBins {
    std::vector<std::uint32_t> begin;                  ///< grid.count() + 1 offsets into records
    std::vector<SplatRecord> records;                  ///< per tile, in visiting order
    std::vector<footprint::EllipticalFootprint> each;  ///< perspective: per chunk position
    std::vector<float> sx, sy;                         ///< scratch: per chunk position
    std::vector<PixelRect> rect;                       ///< scratch: footprint boxes
    std::vector<std::uint32_t> visible;                ///< scratch: tiles where visible
    std::vector<std::uint32_t> counts;                 ///< scratch: per part and tile
    std::vector<std::uint32_t> ids;                    ///< scratch: the chunk's splats
    std::vector<std::uint32_t> runs;                   ///< scratch: their runs
};

/// Projects the splats order[0, runs.back()) and bins the visible ones into `out`. `runs`
/// cuts them into runs (run r: positions [runs[r], runs[r + 1])) of splats on one segment
/// of a volume row, first and last at its ends: with `cull`, a run whose box is hidden in
/// every tile it touches is skipped without projecting its inner splats. `tiles` holds
/// each tile's compositing state (row-major over `grid`); with `cull`, a splat is left out
/// of every tile that is opaque over its footprint box there. Returns the splats left out
/// of every tile they touch.
std::size_t binChunk(const SplatProjector& projector, const VisitOrder& order,
                     const std::vector<std::uint32_t>& runs, const TileGrid& grid,
                     const std::vector<TileAccumulator>& tiles, bool cull, ChunkBins& out);

}  // namespace splat
