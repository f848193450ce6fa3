#pragma once
// The reference ray caster's continuous fields, f(x) = sum_i d_i h(|S^-1 (x - x_i)|) and, for
// pre-classification, rho(x) and e(x) likewise (docs/design.md "Reconstructed fields"), evaluated
// exactly (up to the kernel table) at any index-space point:
//  - the splat list is scattered into a dense per-voxel grid (absent splats are 0), so a
//    field sample visits only the (2R + 1)^3 lattice points around it;
//  - a brick grid (4^3 voxels) marks bricks whose points lie within R of a non-zero voxel,
//    so rays can skip the space where the fields are exactly 0 (raySegments);
//  - h is tabulated in u^2 (65536 entries, linear interpolation; its error is far below
//    1e-6 of the peak, see tests/test_reference.cpp): the plain path, any kernel;
//  - the tapered Gaussian (the default kernel) is evaluated separably instead: with
//    q = dx^2 + dy^2 + dz^2, h = N [g(dx^2) g(dy^2) g(dz^2) - e_R (1 + (R^2 - q) / 2 sigma^2)]
//    for q < R^2 (footprint/kernel.h), g(q) = exp(-q / 2 sigma^2) once per axis and sample
//    (AVX2 + FMA where the CPU has them: a degree-7 polynomial after reduction by ln 2,
//    relative error < 2e-7; else a 16384-entry table over [0, R^2], < 2e-8), then the
//    2 ceil(R) lattice points per axis combined in rows with the points at or beyond R
//    masked. Same kernel, same truncation at R; the tests hold the two paths to 2e-6 of each
//    other (tests/test_reference.cpp);
//  - a cell flag per voxel (separable path) says whether the window of lattice points a
//    sample in that cell reads holds any non-zero value: if not the sample is exactly 0.
// Views through the volume (slices, MPR, CPR) evaluate the same fields.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "footprint/kernel.h"
#include "footprint/lanes.h"
#include "splat/classify.h"
#include "splat/error.h"
#include "splat/volume.h"

namespace splat {

constexpr int kBrick = 4;  // brick edge, voxels
constexpr int kLutSize = 1 << 16;

// h(u) tabulated over u^2 in [0, R^2].
class KernelLut {
  public:
    explicit KernelLut(const footprint::Kernel& kernel) {
        const double r = kernel.radius();
        r2Max_ = r * r;
        const double step = r2Max_ / kLutSize;
        inv_ = 1.0 / step;
        values_.resize(kLutSize + 2, 0.0f);
        for (int n = 0; n <= kLutSize; ++n) {
            const double u2 = std::min(n * step, r2Max_);
            values_[n] = n == kLutSize ? 0.0f : float(kernel(std::sqrt(u2)));
        }
    }
    double r2Max() const { return r2Max_; }
    float operator()(double u2) const {
        if (!(u2 < r2Max_)) return 0.0f;
        const double t = u2 * inv_;
        const int n = int(t);
        const float f = float(t - n);
        return values_[n] + f * (values_[n + 1] - values_[n]);
    }

  private:
    double r2Max_ = 0, inv_ = 0;
    std::vector<float> values_;
};

// The tapered Gaussian h(u) = N [exp(-q / s2) - e_R (1 + (R^2 - q) / s2)], q = u^2 < R^2,
// s2 = 2 sigma^2 (footprint/kernel.h), written as N g(dx^2) g(dy^2) g(dz^2) - A + B q with
// g(q) = exp(-q / s2) tabulated over [0, R^2]: the separable form of the same kernel.
class SeparableGaussian {
  public:
    static constexpr int kSize = 1 << 14;
    explicit SeparableGaussian(const footprint::Kernel& kernel) {
        const double r = kernel.radius(), s2 = 2.0 * kernel.sigma() * kernel.sigma();
        const double eR = std::exp(-r * r / s2), n = kernel.normalisation();
        r2_ = float(r * r);
        minusInvS2_ = float(-1.0 / s2);
        n_ = float(n);
        a_ = float(n * eR * (1.0 + r * r / s2));
        b_ = float(n * eR / s2);
        inv_ = float(kSize / (r * r));
        g_.resize(kSize + 2);
        for (int m = 0; m <= kSize + 1; ++m) g_[m] = float(std::exp(-(m * r * r / kSize) / s2));
        window_ = 2 * int(std::ceil(r));
    }
    /// The lattice points one sample can reach per axis: 2 ceil(R) from floor(p) - ceil(R) + 1.
    int window() const { return window_; }
    float r2() const { return r2_; }
    float minusInvS2() const { return minusInvS2_; }  ///< g(q) = exp(q * minusInvS2())
    float n() const { return n_; }
    float a() const { return a_; }
    float b() const { return b_; }
    /// g(q) = exp(-q / s2) for q in [0, R^2] (linear interpolation; relative error < 2e-8).
    float g(float q) const {
        const float t = q * inv_;
        const int m = int(t);
        const float f = t - float(m);
        return g_[m] + f * (g_[m + 1] - g_[m]);
    }

  private:
    float r2_ = 0, minusInvS2_ = 0, n_ = 0, a_ = 0, b_ = 0, inv_ = 0;
    int window_ = 0;
    std::vector<float> g_;
};

#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
// FieldGrid::evalSeparable's rows for W = 4 with AVX2 + FMA (footprint/lanes.h: called only
// where the CPU has them): `at` points at the window's first voxel, the rows `row` and planes
// `plane` floats apart; the weights as in rowsSse2, two lattice points (8 channels) per FMA
// for C = 4, one row per FMA for C = 1; float within a plane, double across planes.
template <int C>
void separableRowsLanes(const float* at, std::ptrdiff_t row, std::ptrdiff_t plane,
                        const float q[3][4], const float g[3][4], const SeparableGaussian& k,
                        double out[C]) {
    // Branch-free: all 16 rows, the weights of points at or beyond R masked to 0 (which rows
    // are inside changes from sample to sample); rows summed in independent registers.
    const __m128 qx = _mm_loadu_ps(q[0]), gx = _mm_loadu_ps(g[0]);
    const __m128 vr2 = _mm_set1_ps(k.r2()), zero = _mm_setzero_ps();
    const __m128 bqx = _mm_fmsub_ps(_mm_set1_ps(k.b()), qx, _mm_set1_ps(k.a()));  // B qx - A
    const __m256i lo01 = _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1);
    const __m256i hi23 = _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3);
    __m256d sum = _mm256_setzero_pd();
    for (int kz = 0; kz < 4; ++kz) {
        __m256 acc8[4];
        __m128 acc4[4];
        for (int jy = 0; jy < 4; ++jy) {
            const float qyz = q[1][jy] + q[2][kz];
            const __m128 qq = _mm_add_ps(qx, _mm_set1_ps(qyz));
            // h = N gx gy gz - A + B (qx + qyz)
            const __m128 h = _mm_fmadd_ps(gx, _mm_set1_ps(k.n() * g[1][jy] * g[2][kz]),
                                          _mm_add_ps(bqx, _mm_set1_ps(k.b() * qyz)));
            const __m128 w =
                _mm_and_ps(h, _mm_and_ps(_mm_cmplt_ps(qq, vr2), _mm_cmpgt_ps(h, zero)));
            const float* r = at + kz * plane + jy * row;
            if constexpr (C == 4) {
                const __m256 w8 = _mm256_castps128_ps256(w);
                acc8[jy] = _mm256_fmadd_ps(
                    _mm256_permutevar8x32_ps(w8, hi23), _mm256_loadu_ps(r + 8),
                    _mm256_mul_ps(_mm256_permutevar8x32_ps(w8, lo01), _mm256_loadu_ps(r)));
            } else {
                acc4[jy] = _mm_mul_ps(w, _mm_loadu_ps(r));
            }
        }
        __m128 p4;
        if constexpr (C == 4) {
            const __m256 a =
                _mm256_add_ps(_mm256_add_ps(acc8[0], acc8[1]), _mm256_add_ps(acc8[2], acc8[3]));
            p4 = _mm_add_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
        } else {
            p4 = _mm_add_ps(_mm_add_ps(acc4[0], acc4[1]), _mm_add_ps(acc4[2], acc4[3]));
        }
        sum = _mm256_add_pd(sum, _mm256_cvtps_pd(p4));
    }
    alignas(32) double s[4];
    _mm256_store_pd(s, sum);
    if constexpr (C == 4)
        for (int c = 0; c < 4; ++c) out[c] = s[c];
    else
        out[0] = (s[0] + s[1]) + (s[2] + s[3]);
}

// exp(x) for x in [-80, 0] (Cody-Waite reduction by ln 2, Taylor polynomial of degree 7
// on |r| <= ln 2 / 2: relative error below 2e-7, float rounding included).
inline __m256 expLanes(__m256 x) {
    const __m256 k = _mm256_round_ps(_mm256_mul_ps(x, _mm256_set1_ps(1.44269504f)),
                                     _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    __m256 r = _mm256_fnmadd_ps(k, _mm256_set1_ps(0.693359375f), x);
    r = _mm256_fnmadd_ps(k, _mm256_set1_ps(-2.12194440e-4f), r);
    __m256 p = _mm256_set1_ps(1.0f / 5040.0f);
    for (const float c :
         {1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f, 1.0f / 6.0f, 0.5f, 1.0f, 1.0f})
        p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(c));
    const __m256i e =
        _mm256_slli_epi32(_mm256_add_epi32(_mm256_cvtps_epi32(k), _mm256_set1_epi32(127)), 23);
    return _mm256_mul_ps(p, _mm256_castsi256_ps(e));
}

// FieldGrid::evalSeparable for W = 4 with AVX2 + FMA: `frac` = p - base per axis (in [1, 2)),
// the twelve per-axis q = d^2 and g(q) in two vectors, then the rows.
template <int C>
void separableLanes(const float* at, std::ptrdiff_t row, std::ptrdiff_t plane, const float frac[3],
                    const SeparableGaussian& k, double out[C]) {
    alignas(32) float q[3][4], g[3][4], qz[8], gz[8];
    const __m256 n = _mm256_setr_ps(0, 1, 2, 3, 0, 1, 2, 3);
    const __m256 dxy = _mm256_sub_ps(
        _mm256_setr_ps(frac[0], frac[0], frac[0], frac[0], frac[1], frac[1], frac[1], frac[1]), n);
    const __m256 dz = _mm256_sub_ps(_mm256_set1_ps(frac[2]), n);
    const __m256 qxy = _mm256_mul_ps(dxy, dxy), qzz = _mm256_mul_ps(dz, dz);
    const __m256 s = _mm256_set1_ps(k.minusInvS2());
    _mm256_store_ps(&q[0][0], qxy);
    _mm256_store_ps(&g[0][0], expLanes(_mm256_mul_ps(qxy, s)));
    _mm256_store_ps(qz, qzz);
    _mm256_store_ps(gz, expLanes(_mm256_mul_ps(qzz, s)));
    for (int m = 0; m < 4; ++m) {
        q[2][m] = qz[m];
        g[2][m] = gz[m];
    }
    separableRowsLanes<C>(at, row, plane, q, g, k, out);
}
FOOTPRINT_LANES_END
#endif

// Dense per-voxel values (C channels interleaved) plus the brick occupancy grid.
template <int C>
struct FieldGrid {
    glm::ivec3 dims{0};
    double radius = 0;
    std::vector<float> values;
    glm::ivec3 nb{0};
    std::vector<std::uint8_t> bricks;
    const KernelLut* lut = nullptr;
    const SeparableGaussian* gauss = nullptr;  ///< the separable path (null: plain path only)
    /// Separable path: per cell floor(p), 1 when its W^3 window holds a non-zero voxel; a
    /// sample whose window is all zero is 0 without the sum (empty space at the kernel's
    /// support, finer than the bricks).
    std::vector<std::uint8_t> windowFlags;

    // Fills windowFlags for windows of w points per axis from floor(p) - (w / 2 - 1) (planes
    // in parallel: each cell is written once per pass, so any thread count gives the same).
    void buildWindowFlags(int w) {
        const std::size_t n = std::size_t(dims.x) * dims.y * dims.z;
        const std::size_t planeSize = std::size_t(dims.x) * dims.y;
        std::vector<std::uint8_t> a(n), b(n);
        tbb::parallel_for(0, dims.z, [&](int k) {
            for (std::size_t v = k * planeSize; v < (k + 1) * planeSize; ++v) {
                bool any = false;
                for (int c = 0; c < C; ++c) any = any || values[v * C + c] != 0.0f;
                a[v] = any;
            }
        });
        // Separable dilation: cell c sees voxels c - (w / 2 - 1) .. c + w / 2 on each axis, as
        // ORs of whole rows (shifted along x, neighbouring rows along y and z).
        const int lo = w / 2 - 1, hi = w / 2;
        const std::size_t stride[3] = {1, std::size_t(dims.x), planeSize};
        for (int axis = 0; axis < 3; ++axis) {
            tbb::parallel_for(0, dims.z, [&](int k) {
                for (int j = 0; j < dims.y; ++j) {
                    const std::size_t row = (std::size_t(k) * dims.y + j) * dims.x;
                    std::uint8_t* out = b.data() + row;
                    std::fill(out, out + dims.x, std::uint8_t(0));
                    const int at = axis == 1 ? j : k;
                    for (int d = -lo; d <= hi; ++d) {
                        if (axis == 0) {
                            const std::uint8_t* in = a.data() + row;
                            for (int i = std::max(0, -d); i < std::min(dims.x, dims.x - d); ++i)
                                out[i] |= in[i + d];
                        } else if (at + d >= 0 && at + d < dims[axis]) {
                            const std::uint8_t* in =
                                a.data() + row + d * std::ptrdiff_t(stride[axis]);
                            for (int i = 0; i < dims.x; ++i) out[i] |= in[i];
                        }
                    }
                }
            });
            std::swap(a, b);
        }
        windowFlags = std::move(a);
    }
    bool windowEmpty(const int base[3], int w) const {
        const std::size_t c =
            (std::size_t(base[2] + w / 2 - 1) * dims.y + (base[1] + w / 2 - 1)) * dims.x +
            std::size_t(base[0] + w / 2 - 1);
        return !windowFlags.empty() && windowFlags[c] == 0;
    }

    std::size_t index(int i, int j, int k) const {
        return ((std::size_t(k) * dims.y + j) * dims.x + i) * C;
    }
    bool brick(int bx, int by, int bz) const {
        return bricks[(std::size_t(bz) * nb.y + by) * nb.x + bx] != 0;
    }

    // Sum of the C channels times h at index position p.
    void eval(const glm::dvec3& p, double out[C]) const {
        if (gauss) switch (gauss->window()) {
                case 2:
                    return evalSeparable<2>(p, out);
                case 4:
                    return evalSeparable<4>(p, out);
                case 6:
                    return evalSeparable<6>(p, out);
                default:
                    break;
            }
        evalPlain(p, out);
    }

    // The separable Gaussian path over the W^3 lattice points around p (W = 2 ceil(R));
    // near the volume's faces, where the window leaves the grid, a zero-padded copy of the
    // window (W = 4 with AVX2 + FMA) or the plain path.
    template <int W>
    void evalSeparable(const glm::dvec3& p, double out[C]) const {
        const SeparableGaussian& k = *gauss;
        const float r2 = k.r2();
        int base[3];
        float q[3][W], g[3][W];
#if defined(FOOTPRINT_HAVE_LANES)
        if constexpr (W == 4)
            if (footprint::cpuHasLanes()) {
                float frac[3];
                bool inside = true;
                for (int a = 0; a < 3; ++a) {
                    const double fl = std::floor(p[a]);
                    if (!(fl >= -8 && fl < dims[a] + 8)) return evalPlain(p, out);
                    base[a] = int(fl) - 1;
                    frac[a] = float(p[a] - double(base[a]));
                    inside = inside && fl >= 1 && fl + 2 < dims[a];
                }
                // A window leaving the grid (near the faces): its lattice points copied, those
                // outside the grid 0, and the same vector rows over the copy.
                if (!inside) {
                    alignas(32) float local[64 * C] = {};
                    for (int kz = 0; kz < 4; ++kz)
                        for (int jy = 0; jy < 4; ++jy)
                            for (int ix = 0; ix < 4; ++ix) {
                                const int i = base[0] + ix, j = base[1] + jy, kk = base[2] + kz;
                                if (i < 0 || j < 0 || kk < 0 || i >= dims.x || j >= dims.y ||
                                    kk >= dims.z)
                                    continue;
                                for (int c = 0; c < C; ++c)
                                    local[((kz * 4 + jy) * 4 + ix) * C + c] =
                                        values[index(i, j, kk) + c];
                            }
                    return separableLanes<C>(local, 4 * C, 16 * C, frac, k, out);
                }
                if (windowEmpty(base, W)) {
                    for (int c = 0; c < C; ++c) out[c] = 0.0;
                    return;
                }
                return separableLanes<C>(values.data() + index(base[0], base[1], base[2]),
                                         std::ptrdiff_t(dims.x) * C,
                                         std::ptrdiff_t(dims.x) * dims.y * C, frac, k, out);
            }
#endif
        for (int a = 0; a < 3; ++a) {
            const double fl = std::floor(p[a]);
            if (!(fl >= W / 2 - 1 && fl + W / 2 < dims[a])) return evalPlain(p, out);
            base[a] = int(fl) - (W / 2 - 1);
            for (int n = 0; n < W; ++n) {
                const float d = float(p[a] - double(base[a] + n));
                q[a][n] = d * d;
                g[a][n] = q[a][n] < r2 ? k.g(q[a][n]) : 0.0f;
            }
        }
        if (windowEmpty(base, W)) {
            for (int c = 0; c < C; ++c) out[c] = 0.0;
            return;
        }
#if defined(__SSE2__)
        if constexpr (W == 4) return rowsSse2(base, q, g, out);
#endif
        double acc[C] = {};
        for (int kz = 0; kz < W; ++kz) {
            if (!(q[2][kz] < r2)) continue;
            for (int jy = 0; jy < W; ++jy) {
                const float qyz = q[1][jy] + q[2][kz];
                if (!(qyz < r2)) continue;
                const float gyz = k.n() * g[1][jy] * g[2][kz];
                const float* row = values.data() + index(base[0], base[1] + jy, base[2] + kz);
                float w[W];
                for (int n = 0; n < W; ++n) {
                    const float qq = q[0][n] + qyz;
                    const float h = g[0][n] * gyz - k.a() + k.b() * qq;
                    w[n] = qq < r2 && h > 0.0f ? h : 0.0f;
                }
                float rowSum[C] = {};
                for (int n = 0; n < W; ++n)
                    for (int c = 0; c < C; ++c) rowSum[c] += w[n] * row[n * C + c];
                for (int c = 0; c < C; ++c) acc[c] += double(rowSum[c]);
            }
        }
        for (int c = 0; c < C; ++c) out[c] = acc[c];
    }

#if defined(__SSE2__)
    // evalSeparable's rows for W = 4 with SSE2: one row of four lattice points per vector,
    // the weights masked to q < R^2 and h > 0, summed in float per plane, in double across.
    void rowsSse2(const int base[3], const float q[3][4], const float g[3][4],
                  double out[C]) const {
        const SeparableGaussian& k = *gauss;
        const float r2 = k.r2();
        const __m128 qx = _mm_loadu_ps(q[0]), gx = _mm_loadu_ps(g[0]);
        const __m128 vr2 = _mm_set1_ps(r2), va = _mm_set1_ps(k.a()), vb = _mm_set1_ps(k.b());
        const __m128 zero = _mm_setzero_ps();
        const __m128 bqx = _mm_sub_ps(_mm_mul_ps(vb, qx), va);  // B qx - A
        __m128d lo = _mm_setzero_pd(), hi = _mm_setzero_pd();
        for (int kz = 0; kz < 4; ++kz) {
            if (!(q[2][kz] < r2)) continue;
            __m128 plane = zero;
            for (int jy = 0; jy < 4; ++jy) {
                const float qyz = q[1][jy] + q[2][kz];
                if (!(qyz < r2)) continue;
                const __m128 qq = _mm_add_ps(qx, _mm_set1_ps(qyz));
                const __m128 gyz = _mm_set1_ps(k.n() * g[1][jy] * g[2][kz]);
                // h = N gx gy gz - A + B (qx + qyz)
                const __m128 h =
                    _mm_add_ps(_mm_add_ps(_mm_mul_ps(gx, gyz), bqx), _mm_set1_ps(k.b() * qyz));
                const __m128 w =
                    _mm_and_ps(h, _mm_and_ps(_mm_cmplt_ps(qq, vr2), _mm_cmpgt_ps(h, zero)));
                const float* row = values.data() + index(base[0], base[1] + jy, base[2] + kz);
                if constexpr (C == 4) {
                    plane = _mm_add_ps(plane,
                                       _mm_mul_ps(_mm_shuffle_ps(w, w, 0x00), _mm_loadu_ps(row)));
                    plane = _mm_add_ps(
                        plane, _mm_mul_ps(_mm_shuffle_ps(w, w, 0x55), _mm_loadu_ps(row + 4)));
                    plane = _mm_add_ps(
                        plane, _mm_mul_ps(_mm_shuffle_ps(w, w, 0xaa), _mm_loadu_ps(row + 8)));
                    plane = _mm_add_ps(
                        plane, _mm_mul_ps(_mm_shuffle_ps(w, w, 0xff), _mm_loadu_ps(row + 12)));
                } else {
                    plane = _mm_add_ps(plane, _mm_mul_ps(w, _mm_loadu_ps(row)));
                }
            }
            lo = _mm_add_pd(lo, _mm_cvtps_pd(plane));
            hi = _mm_add_pd(hi, _mm_cvtps_pd(_mm_movehl_ps(plane, plane)));
        }
        double sum[4];
        _mm_storeu_pd(sum, lo);
        _mm_storeu_pd(sum + 2, hi);
        if constexpr (C == 4)
            for (int c = 0; c < 4; ++c) out[c] = sum[c];
        else
            out[0] = (sum[0] + sum[1]) + (sum[2] + sum[3]);
    }
#endif

    // The plain path: h from the u^2 table at every lattice point within R of p.
    void evalPlain(const glm::dvec3& p, double out[C]) const {
        for (int c = 0; c < C; ++c) out[c] = 0.0;
        const double r = radius, r2 = lut->r2Max();
        const int i0 = std::max(0, int(std::ceil(p.x - r))),
                  i1 = std::min(dims.x - 1, int(std::floor(p.x + r)));
        const int j0 = std::max(0, int(std::ceil(p.y - r))),
                  j1 = std::min(dims.y - 1, int(std::floor(p.y + r)));
        const int k0 = std::max(0, int(std::ceil(p.z - r))),
                  k1 = std::min(dims.z - 1, int(std::floor(p.z + r)));
        if (i0 > i1 || j0 > j1 || k0 > k1) return;
        double dx2[64];
        const int ni = std::min(i1 - i0 + 1, 64);
        for (int n = 0; n < ni; ++n) {
            const double d = p.x - (i0 + n);
            dx2[n] = d * d;
        }
        for (int k = k0; k <= k1; ++k) {
            const double dz = p.z - k, dz2 = dz * dz;
            if (dz2 >= r2) continue;
            for (int j = j0; j <= j1; ++j) {
                const double dy = p.y - j, dyz = dy * dy + dz2;
                if (dyz >= r2) continue;
                const float* row = values.data() + index(i0, j, k);
                for (int n = 0; n < ni; ++n) {
                    const float w = (*lut)(dyz + dx2[n]);
                    if (w == 0.0f) continue;
                    for (int c = 0; c < C; ++c) out[c] += double(w) * double(row[n * C + c]);
                }
            }
        }
    }
};

template <int C>
FieldGrid<C> buildGrid(const Volume& volume, const SplatList& splats, const KernelLut& lut,
                       double radius, const std::array<const std::vector<float>*, C>& channels,
                       const std::vector<float>* alsoMark = nullptr) {
    FieldGrid<C> g;
    g.dims = volume.dims;
    g.radius = radius;
    g.lut = &lut;
    g.values.assign(volume.voxelCount() * C, 0.0f);
    // Brick b covers index positions [-R + b B, -R + (b + 1) B) on each axis.
    g.nb =
        glm::ivec3(glm::ceil((glm::dvec3(volume.dims) - 1.0 + 2.0 * radius) / double(kBrick))) + 1;
    g.bricks.assign(std::size_t(g.nb.x) * g.nb.y * g.nb.z, 0);
    for (const auto* ch : channels)
        if (ch->size() != splats.size())
            throw Error("reference: the splat list lacks the channels this mode needs");
    for (std::size_t s = 0; s < splats.size(); ++s) {
        const int i = splats.i[s], j = splats.j[s], k = splats.k[s];
        if (i >= volume.dims.x || j >= volume.dims.y || k >= volume.dims.z)
            throw Error("reference: splat index outside the volume");
        bool any = false;
        for (int c = 0; c < C; ++c) {
            const float v = (*channels[c])[s];
            g.values[g.index(i, j, k) + c] = v;
            any = any || v != 0.0f;
        }
        // Labels live outside the channels: their voxels' bricks are marked too.
        if (alsoMark && s < alsoMark->size() && (*alsoMark)[s] != 0.0f) any = true;
        if (!any) continue;
        // Points within R of voxel p lie in [p - R, p + R]: bricks floor(p / B) ..
        // floor((p + 2R) / B) in the brick frame that starts at -R.
        const glm::ivec3 p(i, j, k);
        glm::ivec3 lo, hi;
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::max(0, int(std::floor(p[a] / double(kBrick))));
            hi[a] = std::min(g.nb[a] - 1, int(std::floor((p[a] + 2.0 * radius) / kBrick)));
        }
        for (int bz = lo.z; bz <= hi.z; ++bz)
            for (int by = lo.y; by <= hi.y; ++by)
                for (int bx = lo.x; bx <= hi.x; ++bx)
                    g.bricks[(std::size_t(bz) * g.nb.y + by) * g.nb.x + bx] = 1;
    }
    return g;
}

struct Segment {
    double a, b;
};

// Cuts the line p0 + t v (index space, t world units) into the segments crossing marked
// bricks, within [tLo, tHi] and the volume bounds padded by R.
template <int C>
void raySegments(const FieldGrid<C>& g, const glm::dvec3& p0, const glm::dvec3& v, double tLo,
                 double tHi, std::vector<Segment>& out) {
    out.clear();
    const double r = g.radius;
    double tA = tLo, tB = tHi;
    for (int a = 0; a < 3; ++a) {
        const double lo = -r, hi = g.dims[a] - 1 + r;
        if (std::abs(v[a]) < 1e-300) {
            if (p0[a] < lo || p0[a] > hi) return;
            continue;
        }
        double t0 = (lo - p0[a]) / v[a], t1 = (hi - p0[a]) / v[a];
        if (t0 > t1) std::swap(t0, t1);
        tA = std::max(tA, t0);
        tB = std::min(tB, t1);
    }
    if (!(tA < tB)) return;
    const double origin = -r;
    const glm::dvec3 pa = p0 + tA * v;
    glm::ivec3 cell, step;
    glm::dvec3 tMax, tDelta;
    for (int a = 0; a < 3; ++a) {
        cell[a] = std::clamp(int(std::floor((pa[a] - origin) / kBrick)), 0, g.nb[a] - 1);
        if (v[a] > 1e-300) {
            step[a] = 1;
            tMax[a] = (origin + (cell[a] + 1.0) * kBrick - p0[a]) / v[a];
            tDelta[a] = kBrick / v[a];
        } else if (v[a] < -1e-300) {
            step[a] = -1;
            tMax[a] = (origin + cell[a] * double(kBrick) - p0[a]) / v[a];
            tDelta[a] = -kBrick / v[a];
        } else {
            step[a] = 0;
            tMax[a] = std::numeric_limits<double>::infinity();
            tDelta[a] = tMax[a];
        }
    }
    double t = tA;
    while (t < tB) {
        const int axis = tMax.x <= tMax.y ? (tMax.x <= tMax.z ? 0 : 2) : (tMax.y <= tMax.z ? 1 : 2);
        const double tn = std::min(tMax[axis], tB);
        if (tn > t && g.brick(cell.x, cell.y, cell.z)) {
            if (!out.empty() && out.back().b == t)
                out.back().b = tn;
            else
                out.push_back({t, tn});
        }
        t = std::max(t, tn);
        cell[axis] += step[axis];
        tMax[axis] += tDelta[axis];
        if (cell[axis] < 0 || cell[axis] >= g.nb[axis]) break;
    }
}

/// Segmentation labels for the reference: the shown label of every voxel and colour and
/// extinction (a) per label; a point takes the label of its nearest voxel.
struct LabelLookup {
    glm::ivec3 dims{0};
    const std::vector<std::uint16_t>* shown = nullptr;
    const std::vector<glm::vec4>* table = nullptr;
    /// Adds the label's (rho, e) at index-space point p to out[0..3].
    void add(const glm::dvec3& p, float* out) const {
        const glm::ivec3 q(glm::round(p));
        if (q.x < 0 || q.y < 0 || q.z < 0 || q.x >= dims.x || q.y >= dims.y || q.z >= dims.z)
            return;
        const std::size_t label =
            (*shown)[(std::size_t(q.z) * dims.y + std::size_t(q.y)) * dims.x + std::size_t(q.x)];
        if (label == 0 || label >= table->size()) return;
        const glm::vec4 c = (*table)[label];
        out[0] += c.a;
        out[1] += c.r * c.a;
        out[2] += c.g * c.a;
        out[3] += c.b * c.a;
    }
};

/// Which fields a ReferenceField holds.
enum class FieldLayout {
    Density,          ///< f (one channel): post-classified dvr, mip, xray, iso, views
    Emission,         ///< rho, e_r, e_g, e_b: pre-classified dvr
    DensityGradient,  ///< f and the reconstructed central-difference gradient g_x, g_y, g_z
};

/// The reference's exact accelerations, each switchable so that the tests can compare them
/// with the plain path (all on in every renderer).
struct ReferenceAcceleration {
    /// The tapered Gaussian evaluated separably (SeparableGaussian) instead of from the u^2
    /// table at every lattice point.
    bool separableKernel = true;
    /// dvr rays stop once the light still to come cannot change the pixel by more than a
    /// hundredth of the tolerance (reference.cpp, "Early termination"); off: at T < 1e-7.
    bool toleranceTermination = true;
    /// dvr rays refine only the panels (two first steps long) whose own change moves the
    /// pixel (reference.cpp, "Panel adaptivity"); off: every sample of the ray is halved
    /// until the whole ray's pixel changes by at most the tolerance.
    bool panelAdaptive = true;
};

/// The fields of one classified scene (see FieldLayout). Not copyable (the grids point at
/// the kernel table).
class ReferenceField {
  public:
    ReferenceField(const Volume& volume, const SplatList& splats, const footprint::Kernel& kernel,
                   FieldLayout layout, ReferenceAcceleration acceleration = {});
    ReferenceField(const ReferenceField&) = delete;
    ReferenceField& operator=(const ReferenceField&) = delete;

    FieldLayout layout() const { return layout_; }
    bool fourChannels() const { return layout_ != FieldLayout::Density; }
    /// f at a world position (Density and DensityGradient layouts): b + the grid's f - b.
    double density(const Volume& volume, const glm::dvec3& world) const {
        double v[4];
        const glm::dvec3 p = (world - volume.origin) / volume.spacing;
        if (fourChannels()) {
            grid4_.eval(p, v);
        } else {
            grid1_.eval(p, v);
        }
        return v[0] + double(background_);
    }
    const FieldGrid<4>& grid4() const { return grid4_; }
    const FieldGrid<1>& grid1() const { return grid1_; }
    double radius() const { return radius_; }
    /// The kernel's standard deviation along a line, voxels (sqrt of Kernel::variance).
    double kernelDeviation() const { return kernelDeviation_; }
    const ReferenceAcceleration& acceleration() const { return acceleration_; }
    /// Emission layout: max over voxels and channels of e_i / rho_i, which bounds e(x) / rho(x)
    /// everywhere (h >= 0, so e / rho is a weighted mean of the voxels' ratios); infinite when
    /// a voxel emits without extinction.
    double emissionRatioBound() const { return emissionRatioBound_; }

  private:
    KernelLut lut_;
    std::unique_ptr<SeparableGaussian> gauss_;
    ReferenceAcceleration acceleration_;
    double emissionRatioBound_ = std::numeric_limits<double>::infinity();
    double radius_;
    double kernelDeviation_ = 0.5;
    FieldLayout layout_;
    float background_ = 0.0f;  ///< b (the grids hold d_i - b, SplatList::background)
    FieldGrid<4> grid4_;
    FieldGrid<1> grid1_;
};

}  // namespace splat
