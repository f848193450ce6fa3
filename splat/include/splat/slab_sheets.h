#pragma once
// Exact sort-last bricks for the image-aligned splatter (docs/parallel.md). A slab's
// optical depth and emission (or its density integral) are sums over kernels of their sections in
// the slab (docs/design.md "Sheets"), so summing every slab's sheets over the bricks, each brick
// contributing the sections of the kernels of the samples it owns (every kernel once: no ghost
// kernel, no clip plane), and compositing only the sums gives the one-process frame to float
// rounding. The core stays free of MPI: BrickSheets gives one brick's sheets of a group of slabs as
// plain float blocks, the caller sums them (one process: into the same blocks; MPI: onto ranges of
// screen tiles, splat/bricks.h), and SlabCompositor composites the summed blocks of its tiles group
// after group, front to back in visiting order, so memory stays bounded by one group.
//
// Layout of a group of `count` slabs from `first` (visiting order) over tiles [t0, t1):
// tile t's slab first + k is the block at ((t - t0) count + k) B floats, B = channels
// tileSize^2 (channel c, tile-local pixel (x, y) at c tileSize^2 + y tileSize + x), and the
// block's written rectangle at 4 ((t - t0) count + k) ints: (x0, y0, -x1, -y1), tile-local
// and inclusive, combined by the minimum (empty: kNoRect in all four). The rectangles make the
// compositor visit exactly the pixels the one-process sweep visits.
#include <climits>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>

#include "splat/image.h"
#include "splat/scene.h"
#include "splat/settings.h"

namespace splat {

inline constexpr int kNoRect = INT_MAX;

/// The tiles, channels and slabs of an exact bricked frame, the same on every brick.
struct SlabLayout {
    int width = 0, height = 0, tileSize = 32, tiles = 0;
    int channels = 1;         ///< per sheet pixel (the mode's compositing policy)
    std::uint32_t slabs = 0;  ///< of the frame
    std::size_t blockFloats() const { return std::size_t(channels) * tileSize * tileSize; }
};

/// One brick's part of an exact image-aligned frame.
class BrickSheets {
  public:
    /// The kernels of samples [ownLo, ownHi) (indices of `scene`'s volume: a brick loaded
    /// with ghost layers, which only give the gradients their neighbours) as `frame` sees
    /// them: the brick's settings (the whole volume's free camera, renderer sheet, no clip
    /// plane, no early termination). Shades and projects them. `whole`: the geometry of the
    /// whole volume, whose camera's depths the slab grid is laid in (an orthographic
    /// camera's eye sits in front of the volume it is made for).
    BrickSheets(const Scene& scene, const RenderSettings& frame, const glm::ivec3& ownLo,
                const glm::ivec3& ownHi, const Volume& whole);
    ~BrickSheets();
    BrickSheets(BrickSheets&&) noexcept;
    /// The depths its kernels reach, nearest and farthest (world, along the view, from the
    /// whole volume's eye); nearest > farthest when it owns none.
    float nearest() const;
    float farthest() const;
    /// Orders and bins its kernels on the frame's slab grid, from `nearest` to `farthest`
    /// (the extremes over every brick, as slabLayout); returns the layout.
    SlabLayout plan(float nearest, float farthest);
    /// Adds its sections in slabs [first, first + count) of every tile into `blocks` and
    /// widens `rects` (the file comment's layout with t0 = 0).
    void add(std::uint32_t first, std::uint32_t count, float* blocks, int* rects) const;
    std::size_t splats() const;  ///< kernels it owns

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Composites the summed blocks of tiles [tileBegin, tileEnd) of an exact frame.
class SlabCompositor {
  public:
    /// `scene`: any brick's (its transfer function and background value are the frame's);
    /// `frame`: the brick's settings as for BrickSheets.
    SlabCompositor(const Scene& scene, const RenderSettings& frame, const SlabLayout& layout,
                   int tileBegin, int tileEnd);
    ~SlabCompositor();
    /// Composites slabs [first, first + count), which follow the slabs composited before in
    /// visiting order (the file comment's layout with t0 = tileBegin).
    void composite(std::uint32_t first, std::uint32_t count, const float* blocks, const int* rects);
    /// The partial frame: its tiles resolved (no background), zero elsewhere.
    Image image() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The layout of a frame with `settings` (as a brick's, for its tiles and channels) of the
/// volume `whole` whose kernels reach depths [nearest, farthest] (none: nearest > farthest),
/// as every process computes it, with or without a brick.
SlabLayout slabLayout(const RenderSettings& settings, const Volume& whole, float nearest,
                      float farthest);

/// Slabs per group so that one group of blocks of the whole frame fits in `bytes` (at least 1).
std::uint32_t slabGroup(const SlabLayout& layout, std::size_t bytes);

}  // namespace splat
