// Fill-rate limit of this machine for footprint splatting: a minimal AVX2 + FMA kernel that
// does only what every footprint pixel must do (r^2 of the pixel centre in the footprint
// ellipse, a weight from r^2, four channels accumulated into a 32 x 32 tile sheet), with
// nothing else of a renderer around it (no table, no binning, no compositing). Its rate,
// footprint-box pixels per second counted as RenderStats::footprintPixels counts them, is
// the ceiling the benchmark (tools/bench/vs_vtk.py) prints beside each renderer's rate.
//
//   bench_fill [--box PIXELS] [--seconds S] [--threads-list 1,2]
// prints {"box": .., "runs": [{"threads": T, "px_per_s": ..}, ...]}.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "footprint/lanes.h"

namespace {

constexpr int kTile = 32, kStride = 32, kChannels = 4;
constexpr int kPlane = kStride * kTile + 24;  // padded against 4K aliasing, as the sheets

struct Footprint {
    float sx, sy;  // centre, tile pixels
};

#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
/// Accumulates `count` footprints of box edge `box` into `sheet`; returns box pixels.
long long fill(float* sheet, const Footprint* f, int count, int box) {
    const __m256 lane = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
    const float half = 0.5f * float(box);
    const float a = 1.0f / (half * half), gamma = a;  // a circle of radius `half`
    const __m256 va = _mm256_set1_ps(a), one = _mm256_set1_ps(1.0f);
    const __m256 v[kChannels] = {_mm256_set1_ps(0.1f), _mm256_set1_ps(0.2f), _mm256_set1_ps(0.3f),
                                 _mm256_set1_ps(0.4f)};
    long long pixels = 0;
    for (int s = 0; s < count; ++s) {
        const int x0 = std::max(0, int(f[s].sx - half)), y0 = std::max(0, int(f[s].sy - half));
        const int x1 = std::min(kTile - 1, x0 + box - 1), y1 = std::min(kTile - 1, y0 + box - 1);
        const __m256 lastX = _mm256_set1_ps(float(x1) + 0.5f);
        const __m256 firstX = _mm256_set1_ps(float(x0) - 0.5f);
        for (int y = y0; y <= y1; ++y) {
            const float dy = float(y) + 0.5f - f[s].sy;
            const __m256 gyy = _mm256_set1_ps(gamma * dy * dy);
            const __m256 shift = _mm256_set1_ps(0.5f - f[s].sx);
            for (int x = x0 & ~7; x <= x1; x += 8) {
                const __m256 px = _mm256_add_ps(_mm256_set1_ps(float(x)), lane);
                const __m256 q = _mm256_add_ps(px, shift);
                const __m256 r2 = _mm256_fmadd_ps(_mm256_mul_ps(va, q), q, gyy);
                // weight (1 - r^2)^2 inside the circle and the box, 0 elsewhere
                const __m256 t = _mm256_max_ps(_mm256_sub_ps(one, r2), _mm256_setzero_ps());
                const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(px, lastX, _CMP_LT_OQ),
                                                    _mm256_cmp_ps(px, firstX, _CMP_GT_OQ));
                const __m256 w = _mm256_and_ps(inside, _mm256_mul_ps(t, t));
                for (int c = 0; c < kChannels; ++c) {
                    float* p = sheet + c * kPlane + y * kStride + x;
                    _mm256_storeu_ps(p, _mm256_fmadd_ps(v[c], w, _mm256_loadu_ps(p)));
                }
            }
        }
        pixels += (x1 - x0 + 1) * (y1 - y0 + 1);
    }
    return pixels;
}
FOOTPRINT_LANES_END
#endif

double rate(int threads, int box, double seconds) {
#if defined(FOOTPRINT_HAVE_LANES)
    if (!footprint::cpuHasLanes()) return 0;
    constexpr int kBatch = 4096;
    std::vector<long long> pixels(std::size_t(threads), 0);
    std::vector<std::thread> pool;
    const auto start = std::chrono::steady_clock::now();
    const auto until = start + std::chrono::duration<double>(seconds);
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            std::mt19937 rng(unsigned(t) + 1);
            std::uniform_real_distribution<float> pos(0.5f * box, kTile - 0.5f * box);
            std::vector<Footprint> f(kBatch);
            for (auto& p : f) p = {pos(rng), pos(rng)};
            std::vector<float> sheet(std::size_t(kChannels) * kPlane + 8, 0.0f);
            while (std::chrono::steady_clock::now() < until) {
                pixels[std::size_t(t)] += fill(sheet.data(), f.data(), kBatch, box);
                std::fill(sheet.begin(), sheet.end(), 0.0f);  // keep values finite, as a flush
            }
        });
    for (auto& th : pool) th.join();
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    long long total = 0;
    for (long long p : pixels) total += p;
    return double(total) / s;
#else
    (void)threads, (void)box, (void)seconds;
    return 0;
#endif
}

}  // namespace

int main(int argc, char** argv) {
    int box = 7;
    double seconds = 1.0;
    std::string list = "1,2";
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--box"))
            box = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--seconds"))
            seconds = std::atof(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--threads-list"))
            list = argv[i + 1];
        else {
            std::fprintf(stderr,
                         "usage: bench_fill [--box 1..24] [--seconds S] [--threads-list 1,2]\n");
            return 2;
        }
    }
    if (box < 1 || box > 24 || !(seconds > 0) || seconds > 60) {
        std::fprintf(stderr, "bench_fill: error: --box must be 1..24 and --seconds in (0, 60]\n");
        return 2;
    }
    std::printf("{\"box\": %d, \"runs\": [", box);
    std::stringstream threads(list);
    bool first = true;
    for (std::string item; std::getline(threads, item, ',');) {
        const int t = std::max(1, std::atoi(item.c_str()));
        std::printf("%s{\"threads\": %d, \"px_per_s\": %.4g}", first ? "" : ", ", t,
                    rate(t, box, seconds));
        first = false;
    }
    std::printf("]}\n");
    return 0;
}
