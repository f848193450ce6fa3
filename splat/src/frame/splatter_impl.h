#pragma once
// Template definitions for splatter.h.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace splat {

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

template <int NCh, class TileFn>
Image renderTiles(const FrameInputs& in, const TileBins& bins, const std::vector<float>& pathScale,
                  RenderStats* stats, TileFn&& tileFn) {
    const TileGrid& g = bins.grid;
    const auto start = std::chrono::steady_clock::now();
    Image image(g.width, g.height);
    std::vector<TileCounters> counters(std::size_t(g.count()));
    auto work = [&] {
        tbb::parallel_for(0, g.count(), 1, [&](int t) {
            const DenormalsAreZero ftz;  // footprint tails must not hit slow denormal paths
            const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
            const int w = std::min(g.tileSize, g.width - ox),
                      h = std::min(g.tileSize, g.height - oy);
            TileAccumulator acc(
                w, h, in.settings.order,
                in.settings.mode == RenderMode::Dvr ? in.settings.earlyTermination : 0.0);
            if (bins.begin[t] != bins.begin[t + 1]) {
                std::vector<float> tileScale;
                if (!pathScale.empty()) {
                    tileScale.resize(std::size_t(w) * h);
                    for (int y = 0; y < h; ++y)
                        for (int x = 0; x < w; ++x)
                            tileScale[y * w + x] =
                                pathScale[std::size_t(oy + y) * g.width + ox + x];
                }
                tileFn(t, acc, tileScale.empty() ? nullptr : tileScale.data(), counters[t]);
            }
            acc.resolve(image, ox, oy, in.settings.mode, in.settings.background);
        });
    };
    if (in.settings.threads > 0) {
        tbb::task_arena arena(in.settings.threads);
        arena.execute(work);
    } else {
        work();
    }
    if (stats) {
        stats->tilesMs = msSince(start);
        for (const auto& c : counters) {
            stats->footprintPixels += c.footprintPixels;
            stats->sheets += c.sheets;
            stats->culledSplats += c.culled;
        }
    }
    return image;
}

}  // namespace splat
