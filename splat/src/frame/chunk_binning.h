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

/// The tiles' opaque 4x4 blocks at the start of a chunk, one bit per block (early splat
/// elimination; all clear unless `cull`). With `only` (one flag per tile), the tiles not
/// flagged count as opaque everywhere: a frame of those tiles alone bins and draws nothing
/// for the others, and skips the bricks that reach none of its tiles.
class Occlusion {
  public:
    Occlusion(const TileGrid& grid, const std::vector<TileAccumulator>& tiles, bool cull,
              const std::vector<std::uint8_t>* only = nullptr);
    bool enabled() const { return cull_; }
    /// True unless tile (tx, ty) is opaque over every block the box `r` (image pixels)
    /// touches.
    bool visible(const PixelRect& r, int tx, int ty) const {
        const int t = ty * g_.tilesX + tx;
        const std::uint64_t m = mask_[std::size_t(t)];
        if (m == 0) return true;
        const int ox = tx * g_.tileSize, oy = ty * g_.tileSize;
        const PixelRect c = clipToTile(r, g_, ox, oy);
        const int bx0 = (c.x0 - ox) / kBlock, bx1 = (c.x1 - ox) / kBlock;
        const int by0 = (c.y0 - oy) / kBlock, by1 = (c.y1 - oy) / kBlock;
        const int bx = blocksX_[std::size_t(t)];
        const std::uint64_t row = ((std::uint64_t(2) << (bx1 - bx0)) - 1) << bx0;
        for (int y = by0; y <= by1; ++y)
            if ((m >> (y * bx) & row) != row) return true;
        return false;
    }
    /// True unless every tile the (non-empty) box touches is opaque over it.
    bool visible(const PixelRect& r) const;

  private:
    static constexpr int kBlock = 4;  ///< TileAccumulator's early-termination blocks, pixels
    const TileGrid& g_;
    bool cull_;
    std::vector<std::uint64_t> mask_;
    std::vector<int> blocksX_;
};

/// Whether splats centred in an index-space box may still show in an orthographic view
/// (a brick of the volume tested as one, before its splats are even listed); always true
/// without culling or in perspective.
class BrickTest {
  public:
    BrickTest(const SplatProjector& projector, const Occlusion& occlusion)
        : projector_(projector), occlusion_(occlusion) {}
    bool active() const { return occlusion_.enabled() && !projector_.perspective(); }
    bool operator()(const glm::ivec3& lo, const glm::ivec3& hi) const {
        if (!active()) return true;
        const PixelRect r = projector_.boxOfIndexBox(lo, hi);
        return !r.empty() && occlusion_.visible(r);
    }

  private:
    const SplatProjector& projector_;
    const Occlusion& occlusion_;
};

/// One splat as the tile sweep reads it: its index, its position in the chunk, its screen
/// centre, its slice along the sheet axis and its palette entry (made by ChunkRecords from a
/// RunRecord and the chunk's arrays).
struct SplatRecord {
    std::uint32_t id, local;
    float sx, sy;
    std::uint16_t slice;  ///< SplatRecordFields::slice[id] (0 without)
    std::uint16_t value;  ///< SplatRecordFields::value[id] (0 without)
};

/// One entry of a tile's list: a run of `count` splats at consecutive chunk positions from
/// `local`, all in one sheet (their `slice`), of which at least the run's box touches the
/// tile where it was not yet opaque (8 bytes; a splat that does not reach the tile or is
/// hidden there is left out by the sweep's own per-splat tests). Binning and sorting by sheet
/// handle a run of up to a cell's splats as one entry, not each splat.
struct RunRecord {
    std::uint32_t local;
    std::uint16_t count;
    std::uint16_t slice;
};

/// The per-splat arrays binChunk copies into each record (either may be null).
struct SplatRecordFields {
    const std::uint16_t* slice = nullptr;  ///< slice index along the sheet axis
    const std::uint16_t* value = nullptr;  ///< palette index (SplatList::emissionIndex)
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
/// order (binning sorts each tile's records by sheet, stably), cut into runs along lines of
/// voxels (binChunk), and may leave out the splats of bricks `visible` says are hidden
/// (returning how many it left out). Its cutter spans one sheet per splat (a ring of one),
/// so no sheet is pending between chunks.
struct SheetChunks {
    std::size_t count = 0;
    std::function<std::size_t(std::size_t, std::vector<std::uint32_t>&, std::vector<std::uint32_t>&,
                              const BrickTest& visible)>
        gather;
};

/// One chunk's splats binned to tiles (arrays reused from chunk to chunk and frame to frame).
struct ChunkBins {
    std::vector<std::uint32_t> begin;                  ///< grid.count() + 1 offsets into records
    std::vector<RunRecord> records;                    ///< per tile, in visiting order
    std::vector<footprint::EllipticalFootprint> each;  ///< perspective: per chunk position
    std::vector<float> sx, sy;                         ///< per chunk position
    std::vector<std::uint16_t> value;                  ///< per chunk position (fields.value)
    std::vector<PixelRect> rect;                       ///< scratch: boxes of the entries
    std::vector<std::uint32_t> visible;                ///< scratch: tiles where visible
    std::vector<std::uint32_t> entry;                  ///< scratch: splats per entry
    std::vector<std::uint32_t> counts;                 ///< scratch: per part and tile
    std::vector<std::uint32_t> ids;                    ///< scratch: the chunk's splats
    std::vector<std::uint32_t> runs;                   ///< scratch: their runs
};

/// Projects the splats order[0, runs.back()) and bins the visible ones into `out`. `runs`
/// cuts them into runs (run r: positions [runs[r], runs[r + 1])) of splats on one line of
/// voxels (a segment of a volume row or column), first and last at its ends. In an
/// orthographic view a run whose splats share a sheet (the slices of its ends are equal: the
/// slice index is monotone along a line) is one entry, binned by the box of its centres'
/// footprints; every other splat is an entry of its own, binned by its footprint box. With
/// culling, a run whose box is hidden in every tile it touches is skipped without projecting
/// its inner splats, and an entry is left out of every tile that `occlusion` says is opaque
/// over its box there (the sweep tests each splat again: as opacity only grows, it draws
/// exactly the splats that per-splat binning would have listed, in the same order).
/// Returns the splats left out of every tile they touch.
std::size_t binChunk(const SplatProjector& projector, const VisitOrder& order,
                     const std::vector<std::uint32_t>& runs, const TileGrid& grid,
                     const Occlusion& occlusion, const SplatRecordFields& fields, ChunkBins& out);

}  // namespace splat
