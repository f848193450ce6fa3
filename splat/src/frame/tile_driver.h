#pragma once
// Pipeline stage "tiles", shared by both splatters: every screen tile, in parallel, owns
// its ring of sheet buffers and its compositing state (so threads never share a pixel and
// the image does not depend on the thread count) and sweeps its splats in visiting order:
//
//   for each splat: clip to the tile -> occlusion test -> footprint ellipse and values
//                   -> the splatter's Cutter adds the kernel to the sheets it spans
//   when the sweep passes a sheet: flush it through the compositing policy (sheet -> sample
//                   -> accumulate); stop when the whole tile is opaque
//   then: resolve the tile into the image.
//
// A Cutter says which sheet a splat starts in (key, in visiting order), how many sheets it
// spans, and how its kernel is cut into them; that is all that differs between the
// axis-aligned (one sheet: the whole footprint) and the image-aligned splatter (every slab
// it crosses: slab sections).
#include <tbb/parallel_for.h>

#include <chrono>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "frame/compositing.h"
#include "frame/projection.h"
#include "frame/sheet_buffer.h"
#include "frame/tile_binning.h"
#include "model/scene_impl.h"
#include "splat/camera.h"

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace splat {

/// How a view cuts the kernels into sheets: what the order stage decided.
struct SheetPlan {
    std::uint32_t sheets = 0;  ///< sheets of the view, in visiting order
    std::uint32_t ring = 1;    ///< sheet buffers a tile keeps: most sheets one splat spans + 1
    float pathLength = 1;      ///< world length of a ray's path through one sheet
    glm::dvec3 normal{0.0, 0.0, 1.0};  ///< sheet normal, for perspective path lengths
    /// Axis-aligned: the volume axis the sheets are perpendicular to, the ray direction's
    /// sign along it, and whether the visiting order runs up the slice index.
    int axis = -1, sign = 0;
    bool ascending = true;
    /// Image-aligned: depth of the first slab boundary and the slab thickness (world).
    float depthOrigin = 0, thickness = 1;
};

/// What the tile stage reads.
struct TileInputs {
    const Scene::Impl& scene;
    const Camera& camera;
    const RenderSettings& settings;
    const ProjectedSplats& proj;
    const TileBins& bins;
    const SheetPlan& plan;
    const float *er, *eg, *eb;      ///< emission to splat: the list's own or this view's shaded
    const PolicyContext& policy;    ///< the frame's compositing policy and its parameters
    Image* isoPositions = nullptr;  ///< iso: per pixel, the hit's fractional sheet position
};

/// Per-tile counters, summed into RenderStats.
struct TileCounters {
    std::size_t footprintPixels = 0, sheets = 0, culled = 0;
};

/// Flushes denormal floats to zero in this thread while in scope. Kernel tails multiply
/// tiny weights; denormal arithmetic is ~100x slower on x86 and changes no visible value.
class DenormalsAreZero {
  public:
#if defined(__SSE__)
    DenormalsAreZero() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040); }
    ~DenormalsAreZero() { _mm_setcsr(saved_); }

  private:
    unsigned saved_;
#endif
};

/// Per-pixel path-length factor of perspective rays through sheets with normal `axis`:
/// |view . axis| / |dir . axis|; empty for orthographic views.
std::vector<float> perspectivePathScale(const Camera& camera, const glm::dvec3& axis);

/// The values a splat contributes to a sheet, in the channels of the policy's source.
template <class Policy>
inline void splatValues(const TileInputs& in, std::uint32_t id, float (&v)[Policy::kChannels]) {
    const SplatList& s = in.scene.splats;
    if constexpr (Policy::kSource == SheetSource::Emission) {
        v[0] = s.extinction[id];
        v[1] = in.er[id];
        v[2] = in.eg[id];
        v[3] = in.eb[id];
    } else if constexpr (Policy::kSource == SheetSource::Labels) {
        v[0] = s.extinction[id];
        v[1] = in.er[id];
        v[2] = in.eg[id];
        v[3] = in.eb[id];
        v[4] = 1.0f;  // every splat competes for the pixel's label, the background too
        v[5] = s.label[id];
    } else if constexpr (Policy::kSource == SheetSource::DensityGradient) {
        v[0] = s.density[id];
        v[1] = s.gx[id];
        v[2] = s.gy[id];
        v[3] = s.gz[id];
    } else {
        v[0] = s.density[id];
    }
}

/// The sweep of one tile (see the file comment).
template <class Policy, class Cutter>
void sweepTile(const TileInputs& in, const Policy& policy, const Cutter& cutter, int t,
               TileAccumulator& acc, const float* tileScale, TileCounters& cnt) {
    constexpr int NCh = Policy::kChannels;
    const TileBins& bins = in.bins;
    const int ox = (t % bins.grid.tilesX) * bins.grid.tileSize;
    const int oy = (t / bins.grid.tilesX) * bins.grid.tileSize;
    const std::uint32_t ring = in.plan.ring;
    std::vector<SheetBuffer<NCh>> sheets;
    sheets.reserve(ring);
    for (std::uint32_t k = 0; k < ring; ++k) sheets.emplace_back(ox, oy, acc.width(), acc.height());
    std::vector<SheetBuffer<NCh>*> target(ring);
    std::uint32_t next = bins.begin[t];
    const std::uint32_t end = bins.begin[t + 1];
    // Sweep position (sheet index in visiting order) and the last position that has
    // contributions pending in the ring.
    std::uint32_t step = cutter.key(bins.splats[next]), pendingEnd = step;
    bool pending = false;
    while (next < end || pending) {
        if (!pending) step = std::max(step, cutter.key(bins.splats[next]));  // skip empty sheets
        for (; next < end && cutter.key(bins.splats[next]) == step; ++next) {
            const std::uint32_t id = bins.splats[next];
            const PixelRect r = clipToTile(in.proj.rect[id], bins.grid, t);
            if (acc.rectOpaque(r.x0 - ox, r.y0 - oy, r.x1 - ox, r.y1 - oy)) {
                ++cnt.culled;
                continue;
            }
            const std::uint32_t n = cutter.span(id);
            for (std::uint32_t j = 0; j < n; ++j) target[j] = &sheets[(step + j) % ring];
            float v[NCh];
            splatValues<Policy>(in, id, v);
            cnt.footprintPixels += cutter.cut(target.data(), id, v, in.proj.sx[id], in.proj.sy[id],
                                              in.proj.ellipse(id), r);
            pendingEnd = std::max(pendingEnd, step + n - 1);
            pending = true;
        }
        SheetBuffer<NCh>& sheet = sheets[step % ring];
        if (sheet.dirty()) {
            acc.setSheet(step);
            sheet.flush(acc, policy, in.plan.pathLength, tileScale);
            ++cnt.sheets;
        }
        pending = step < pendingEnd;
        ++step;
        if (acc.allOpaque()) {
            cnt.culled += end - next;
            break;
        }
    }
}

/// Runs sweepTile over every tile in parallel and writes the tiles into the (partial)
/// image; the background is applied afterwards by the frame.
template <class Policy, class Cutter>
Image rasterizeTiles(const TileInputs& in, const Policy& policy, const Cutter& cutter,
                     RenderStats* stats) {
    const auto start = std::chrono::steady_clock::now();
    const TileGrid& g = in.bins.grid;
    const std::vector<float> pathScale = perspectivePathScale(in.camera, in.plan.normal);
    Image image(g.width, g.height);
    std::vector<TileCounters> counters(std::size_t(g.count()));
    tbb::parallel_for(0, g.count(), 1, [&](int t) {
        const DenormalsAreZero ftz;  // footprint tails must not hit slow denormal paths
        const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
        const int w = std::min(g.tileSize, g.width - ox), h = std::min(g.tileSize, g.height - oy);
        constexpr bool surface = kSurfacePolicy<Policy>;  // issue 13: also when clipped
        TileAccumulator acc(w, h, in.settings.order,
                            Policy::kTerminates ? in.settings.quality.earlyTermination : 0.0,
                            surface);
        acc.setOrigin(ox, oy, g.width);  // issue 13: per-pixel clip cut
        if (in.bins.begin[t] != in.bins.begin[t + 1]) {
            std::vector<float> tileScale;
            if (!pathScale.empty()) {
                tileScale.resize(std::size_t(w) * h);
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x)
                        tileScale[y * w + x] = pathScale[std::size_t(oy + y) * g.width + ox + x];
            }
            sweepTile(in, policy, cutter, t, acc, tileScale.empty() ? nullptr : tileScale.data(),
                      counters[t]);
        }
        acc.resolve(image, ox, oy, in.settings.mode);
        if (surface && in.isoPositions) acc.resolvePositions(*in.isoPositions, ox, oy);
    });
    if (stats) {
        stats->pathScalePixels = pathScale.size();
        stats->tilesMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        for (const auto& c : counters) {
            stats->footprintPixels += c.footprintPixels;
            stats->sheets += c.sheets;
            stats->culledSplats += c.culled;
        }
    }
    return image;
}

/// rasterizeTiles with the compositing policy of the frame's mode.
template <class Cutter>
Image rasterizeWithPolicy(const TileInputs& in, const Cutter& cutter, RenderStats* stats) {
    return withPolicy(in.policy,
                      [&](const auto& policy) { return rasterizeTiles(in, policy, cutter, stats); });
}

}  // namespace splat
