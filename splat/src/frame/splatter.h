#pragma once
// What both splatters share: the inputs of a frame, the visiting order of the splats, and
// the driver that renders screen tiles in parallel (each tile owns its sheet buffer and
// its compositing state) and assembles the image. The two splatters differ only in how
// they cut kernels into sheets: axis_splatter.cpp and image_aligned_splatter.cpp.
#include <chrono>
#include <cstdint>
#include <vector>

#include "footprint/footprint_table.h"
#include "footprint/slab_table.h"
#include "projection.h"
#include "sheet_buffer.h"
#include "splat/render.h"
#include "tile_binning.h"

namespace splat {

/// Per-frame arrays, kept by the Renderer and reused so that a sequence of frames does not
/// allocate (and fault in) fresh memory every frame.
struct FrameWorkspace {
    ProjectedSplats proj;
    TileBins bins;
    std::vector<std::uint32_t> order, key, first, last;
    std::vector<float> r, g, b;  ///< shaded emission of this view
};

struct FrameInputs {
    const Volume& volume;
    const SplatList& splats;
    const Camera& camera;
    const RenderSettings& settings;  ///< transfer already resolved
    const footprint::FootprintTable& table;
    const footprint::FootprintPoly* poly;          ///< fast evaluation of `table`, if accurate enough
    const footprint::SlabTable* slabs;  ///< image-aligned only
    const TransferTable& transfer;
    FrameWorkspace& work;
    /// Emission to splat: the list's own, or the shaded emission of this view.
    const float *er, *eg, *eb;
};

/// Per-tile counters, summed into RenderStats.
struct TileCounters {
    std::size_t footprintPixels = 0, sheets = 0, culled = 0;
};

/// A copy of `splats` sorted (stably) by slice index along `axis` (0 = i, 1 = j, 2 = k), so
/// that a frame visiting slices in order reads the list sequentially.
SplatList sortedBySlice(const SplatList& splats, int axis);

/// Milliseconds since `start`.
inline double msSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

/// Stable counting sort: splat indices ordered by key[s] in [0, keys).
void orderByKey(const std::vector<std::uint32_t>& key, std::uint32_t keys,
                std::vector<std::uint32_t>& order);

/// Per-pixel ray direction factor for perspective views, 1 / |dir . axis| * |view . axis|
/// style path-length scales; empty for orthographic views. `axis` is the sheet normal.
std::vector<float> perspectivePathScale(const Camera& camera, const glm::dvec3& axis);

/// The values a splat contributes to a sheet: (rho, e_r, e_g, e_b) or (density).
template <int NCh>
inline void splatValues(const FrameInputs& in, std::size_t i, float (&v)[NCh]) {
    if constexpr (NCh == 4) {
        v[0] = in.splats.extinction[i];
        v[1] = in.er[i];
        v[2] = in.eg[i];
        v[3] = in.eb[i];
    } else {
        v[0] = in.splats.density[i];
    }
}

/// Calls f.operator()<4>() for pre-classified dvr (extinction and emission per sheet
/// pixel) and f.operator()<1>() otherwise (density).
template <class F>
Image withChannels(const RenderSettings& s, F&& f) {
    return SheetModel{s.mode, s.classification, nullptr}.channels() == 4
               ? f.template operator()<4>()
               : f.template operator()<1>();
}

/// Runs `tileFn(tileIndex, accumulator, pathScaleOfTile, counters)` for every tile that
/// has splats, in parallel (settings.threads), then writes the tiles into the image.
template <int NCh, class TileFn>
Image renderTiles(const FrameInputs& in, const TileBins& bins, const std::vector<float>& pathScale,
                  RenderStats* stats, TileFn&& tileFn);

}  // namespace splat

#include "splatter_impl.h"
