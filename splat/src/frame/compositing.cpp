// The shared compositing stage (see compositing.h).
#include "compositing.h"

#include <algorithm>

#include "footprint/lanes.h"
#include "splat/error.h"

namespace splat {

namespace {
constexpr int kBlock = 4;  // early-termination granularity, pixels (64 blocks per 32x32 tile)

#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
/// alpha = 1 - exp(-tau) and k = alpha / tau for eight optical depths (the lanes of
/// sampleFromOpticalDepth). |tau| < 1/2: k from its Taylor series to tau^8 (relative error
/// < 3e-9, and no cancellation), alpha = k tau; otherwise exp(-tau) by range reduction to
/// |r| <= ln2 / 2 and a degree-7 Taylor polynomial (relative error < 3e-9), k = alpha / tau.
/// Eight lanes all below 1/2 (most samples of thin sheets) return before the exponential and
/// its division, with the lanes the blend would have kept.
inline void opacityLanes(__m256 tau, __m256& alpha, __m256& k) {
    const __m256 one = _mm256_set1_ps(1.0f);
    // Series: k = sum_n (-tau)^n / (n + 1)!, Horner from the highest term.
    const __m256 t = _mm256_sub_ps(_mm256_setzero_ps(), tau);
    __m256 ks = _mm256_set1_ps(1.0f / 362880.0f);
    for (float c : {1.0f / 40320.0f, 1.0f / 5040.0f, 1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f,
                    1.0f / 6.0f, 0.5f, 1.0f})
        ks = _mm256_fmadd_ps(ks, t, _mm256_set1_ps(c));
    const __m256 big = _mm256_cmp_ps(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), tau),
                                     _mm256_set1_ps(0.5f), _CMP_GE_OQ);
    if (_mm256_testz_ps(big, big)) {  // every lane on the series: no exponential to blend in
        alpha = _mm256_mul_ps(ks, tau);
        k = ks;
        return;
    }
    // exp(x), x = -tau clamped to where float exp is finite and normal.
    const __m256 x = _mm256_min_ps(_mm256_max_ps(t, _mm256_set1_ps(-87.0f)), _mm256_set1_ps(87.0f));
    const __m256 n = _mm256_round_ps(_mm256_mul_ps(x, _mm256_set1_ps(1.44269504088896341f)),
                                     _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    __m256 r = _mm256_fnmadd_ps(n, _mm256_set1_ps(0.693145751953125f), x);
    r = _mm256_fnmadd_ps(n, _mm256_set1_ps(1.42860682030941723212e-6f), r);
    __m256 p = _mm256_set1_ps(1.0f / 5040.0f);
    for (float c : {1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f, 1.0f / 6.0f, 0.5f, 1.0f, 1.0f})
        p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(c));
    const __m256i e =
        _mm256_slli_epi32(_mm256_add_epi32(_mm256_cvtps_epi32(n), _mm256_set1_epi32(127)), 23);
    const __m256 ex = _mm256_mul_ps(p, _mm256_castsi256_ps(e));
    const __m256 alphaBig = _mm256_sub_ps(one, ex);
    alpha = _mm256_blendv_ps(_mm256_mul_ps(ks, tau), alphaBig, big);
    // Division only where it is taken (|tau| >= 1/2 there).
    k = _mm256_blendv_ps(ks, _mm256_div_ps(alphaBig, _mm256_blendv_ps(one, tau, big)), big);
}

/// Composites eight samples (optical depth tau, emission er, eg, eb) into the pixels at R, G,
/// B, A of the lanes in `mask` (Full: all eight, by plain loads and stores: masked stores cost
/// several times a plain one on some processors, AMD's among them).
template <bool Full>
inline void compositeLanes(float* R, float* G, float* B, float* A, bool frontToBack, __m256i mask,
                           __m256 tau, __m256 er, __m256 eg, __m256 eb) {
    const __m256 one = _mm256_set1_ps(1.0f);
    __m256 alpha, k;
    opacityLanes(tau, alpha, k);
    const __m256 cr = _mm256_mul_ps(k, er), cg = _mm256_mul_ps(k, eg), cb = _mm256_mul_ps(k, eb);
    auto load = [&](const float* p) {
        if constexpr (Full) return _mm256_loadu_ps(p);
        return _mm256_maskload_ps(p, mask);
    };
    auto store = [&](float* p, __m256 x) {
        if constexpr (Full)
            _mm256_storeu_ps(p, x);
        else
            _mm256_maskstore_ps(p, mask, x);
    };
    const __m256 a = load(A), r = load(R), g = load(G), b = load(B);
    if (frontToBack) {
        const __m256 t = _mm256_sub_ps(one, a);
        store(R, _mm256_fmadd_ps(t, cr, r));
        store(G, _mm256_fmadd_ps(t, cg, g));
        store(B, _mm256_fmadd_ps(t, cb, b));
        store(A, _mm256_fmadd_ps(t, alpha, a));
    } else {
        const __m256 t = _mm256_sub_ps(one, alpha);
        store(R, _mm256_fmadd_ps(t, r, cr));
        store(G, _mm256_fmadd_ps(t, g, cg));
        store(B, _mm256_fmadd_ps(t, b, cb));
        store(A, _mm256_fmadd_ps(t, a, alpha));
    }
}

void compositeOpticalDepthsLanes(float* R, float* G, float* B, float* A, bool frontToBack, int n,
                                 const float* tau, const float* er, const float* eg,
                                 const float* eb) {
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    for (int i = 0; i < n; i += 8) {
        const __m256i mask = _mm256_cmpgt_epi32(_mm256_set1_epi32(n - i), lane);
        if (n - i >= 8)
            compositeLanes<true>(R + i, G + i, B + i, A + i, frontToBack, mask,
                                 _mm256_loadu_ps(tau + i), _mm256_loadu_ps(er + i),
                                 _mm256_loadu_ps(eg + i), _mm256_loadu_ps(eb + i));
        else
            compositeLanes<false>(
                R + i, G + i, B + i, A + i, frontToBack, mask, _mm256_maskload_ps(tau + i, mask),
                _mm256_maskload_ps(er + i, mask), _mm256_maskload_ps(eg + i, mask),
                _mm256_maskload_ps(eb + i, mask));
    }
}

/// compositeOpticalDepthsLanes for samples interleaved (tau, er, eg, eb), which it sets to
/// zero: eight samples are four loads of (sample i, sample i + 4) pairs, transposed in
/// registers; eight samples all +0 (no change to the pixels) are passed over.
void compositeInterleavedLanes(float* R, float* G, float* B, float* A, bool frontToBack, int n,
                               float* samples) {
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    alignas(32) float tail[32];
    for (int i = 0; i < n; i += 8) {
        const __m256i mask = _mm256_cmpgt_epi32(_mm256_set1_epi32(n - i), lane);
        float* at = samples + 4 * std::ptrdiff_t(i);
        const float* s = at;
        if (n - i < 8) {
            std::fill(std::begin(tail), std::end(tail), 0.0f);
            std::copy(at, at + 4 * (n - i), tail);
            s = tail;
        }
        auto pair = [&](int j) { return _mm256_loadu2_m128(s + 4 * (j + 4), s + 4 * j); };
        const __m256 p0 = pair(0), p1 = pair(1), p2 = pair(2), p3 = pair(3);
        const __m256i bits =
            _mm256_castps_si256(_mm256_or_ps(_mm256_or_ps(p0, p1), _mm256_or_ps(p2, p3)));
        if (_mm256_testz_si256(bits, bits)) continue;
        const __m256 lo01 = _mm256_unpacklo_ps(p0, p1), hi01 = _mm256_unpackhi_ps(p0, p1);
        const __m256 lo23 = _mm256_unpacklo_ps(p2, p3), hi23 = _mm256_unpackhi_ps(p2, p3);
        const __m256 tau = _mm256_shuffle_ps(lo01, lo23, 0x44),
                     er = _mm256_shuffle_ps(lo01, lo23, 0xee),
                     eg = _mm256_shuffle_ps(hi01, hi23, 0x44),
                     eb = _mm256_shuffle_ps(hi01, hi23, 0xee);
        if (n - i >= 8) {
            compositeLanes<true>(R + i, G + i, B + i, A + i, frontToBack, mask, tau, er, eg, eb);
            for (int k = 0; k < 32; k += 8) _mm256_storeu_ps(at + k, _mm256_setzero_ps());
        } else {
            compositeLanes<false>(R + i, G + i, B + i, A + i, frontToBack, mask, tau, er, eg, eb);
            std::fill(at, at + 4 * (n - i), 0.0f);
        }
    }
}
FOOTPRINT_LANES_END
#endif
}  // namespace

void TileAccumulator::compositeOpticalDepths(int p, int n, const float* tau, const float* er,
                                             const float* eg, const float* eb) {
#if defined(FOOTPRINT_HAVE_LANES)
    if (footprint::cpuHasLanes()) {
        compositeOpticalDepthsLanes(&r_[p], &g_[p], &b_[p], &a_[p],
                                    order_ == CompositeOrder::FrontToBack, n, tau, er, eg, eb);
        return;
    }
#endif
    for (int i = 0; i < n; ++i)
        composite(p + i, sampleFromOpticalDepth(tau[i], er[i], eg[i], eb[i]));
}

void compositeOpticalDepthRow(float* r, float* g, float* b, float* a, CompositeOrder order, int n,
                              const float* tau, const float* er, const float* eg,
                              const float* eb) {
    const bool frontToBack = order == CompositeOrder::FrontToBack;
#if defined(FOOTPRINT_HAVE_LANES)
    if (footprint::cpuHasLanes()) {
        compositeOpticalDepthsLanes(r, g, b, a, frontToBack, n, tau, er, eg, eb);
        return;
    }
#endif
    for (int i = 0; i < n; ++i) {
        const Sample s = sampleFromOpticalDepth(tau[i], er[i], eg[i], eb[i]);
        const float t = frontToBack ? 1.0f - a[i] : 1.0f - s.alpha;
        if (frontToBack) {
            r[i] += t * s.r;
            g[i] += t * s.g;
            b[i] += t * s.b;
            a[i] += t * s.alpha;
        } else {
            r[i] = s.r + t * r[i];
            g[i] = s.g + t * g[i];
            b[i] = s.b + t * b[i];
            a[i] = s.alpha + t * a[i];
        }
    }
}

void compositeInterleavedRowAndClear(float* r, float* g, float* b, float* a, CompositeOrder order,
                                     int n, float* samples) {
#if defined(FOOTPRINT_HAVE_LANES)
    if (footprint::cpuHasLanes()) {
        compositeInterleavedLanes(r, g, b, a, order == CompositeOrder::FrontToBack, n, samples);
        return;
    }
#endif
    float planes[4][64];
    for (int done = 0; done < n; done += 64) {
        const int m = std::min(64, n - done);
        for (int x = 0; x < m; ++x)
            for (int c = 0; c < 4; ++c) planes[c][x] = samples[4 * (done + x) + c];
        compositeOpticalDepthRow(r + done, g + done, b + done, a + done, order, m, planes[0],
                                 planes[1], planes[2], planes[3]);
    }
    std::fill(samples, samples + 4 * std::ptrdiff_t(n), 0.0f);
}

TileAccumulator::TileAccumulator(int width, int height, CompositeOrder order,
                                 double earlyTermination, bool surface)
    : w_(width),
      h_(height),
      order_(order),
      terminates_(order == CompositeOrder::FrontToBack && earlyTermination > 0),
      threshold_(float(1.0 - earlyTermination)),
      blocksX_((width + kBlock - 1) / kBlock),
      blocksY_((height + kBlock - 1) / kBlock) {
    if (blocksX_ * blocksY_ > 64) throw Error("tile size above 64 pixels is not supported");
    allBlocks_ = blocksX_ * blocksY_ == 64 ? ~std::uint64_t(0)
                                           : (std::uint64_t(1) << (blocksX_ * blocksY_)) - 1;
    const std::size_t n = std::size_t(w_) * h_;
    r_.assign(n, 0.0f);
    g_.assign(n, 0.0f);
    b_.assign(n, 0.0f);
    a_.assign(n, 0.0f);
    if (surface) {
        prev_.assign(n, 0.0f);
        pos_.assign(n, -1.0f);
    }
}

void TileAccumulator::resolvePositions(Image& image, int ox, int oy) const {
    for (int y = 0; y < h_; ++y)
        for (int x = 0; x < w_; ++x) {
            const int p = y * w_ + x;
            const bool hit = !pos_.empty() && a_[p] >= 1.0f;
            image.at(ox + x, oy + y) =
                glm::vec4(hit ? pos_[p] : 0.0f, 0.0f, 0.0f, hit ? 1.0f : 0.0f);
        }
}

bool TileAccumulator::rectOpaque(int x0, int y0, int x1, int y1) const {
    if (!terminates_) return false;
    for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
        for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx)
            if (!(opaqueBlocks_ >> (by * blocksX_ + bx) & 1)) return false;
    return true;
}

void TileAccumulator::updateOpacity(int x0, int y0, int x1, int y1) {
    if (!terminates_) return;
    for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
        for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx) {
            const std::uint64_t bit = std::uint64_t(1) << (by * blocksX_ + bx);
            if (opaqueBlocks_ & bit) continue;
            bool opaque = true;
            const int ye = std::min(h_, (by + 1) * kBlock), xe = std::min(w_, (bx + 1) * kBlock);
            for (int y = by * kBlock; y < ye && opaque; ++y)
                for (int x = bx * kBlock; x < xe; ++x)
                    if (a_[y * w_ + x] < threshold_) {
                        opaque = false;
                        break;
                    }
            if (opaque) opaqueBlocks_ |= bit;
        }
}

void TileAccumulator::resolve(Image& image, int ox, int oy, RenderMode mode) const {
    for (int y = 0; y < h_; ++y)
        for (int x = 0; x < w_; ++x) {
            const int p = y * w_ + x;
            image.at(ox + x, oy + y) = mode == RenderMode::Dvr || mode == RenderMode::Iso
                                           ? glm::vec4(r_[p], g_[p], b_[p], a_[p])
                                           : glm::vec4(r_[p], r_[p], r_[p], 1.0f);
        }
}

void applyBackground(Image& image, RenderMode mode, const glm::vec4& bg, float fieldBackground) {
    if (mode == RenderMode::Mip) {
        for (glm::vec4& out : image.pixels) out = glm::vec4(glm::vec3(out) + fieldBackground, 1.0f);
        return;
    }
    if (mode != RenderMode::Dvr && mode != RenderMode::Iso) return;
    for (glm::vec4& out : image.pixels) out = out + (1.0f - out.a) * bg;
}

}  // namespace splat
