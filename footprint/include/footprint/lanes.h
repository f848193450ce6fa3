#pragma once
// Eight-lane (AVX2 + FMA) evaluation of the footprint tables for the splatters' inner
// loops, kept beside the tables so that no other library re-implements their
// interpolation:
//   FootprintLanes: fp(r^2) of FootprintTable::lookup, from the table (two gathers) or from
//                   a FootprintPoly (permutes and fused multiply-adds, no gathers);
//   FractionLanes:  F(r^2, z) of SlabTable::fraction, bilinear (one 16-byte load per lane
//                   from the interleaved table rows, transposed);
//   GaussianSlabLanes: GaussianSlab's radial part and P(r^2, z) (exp and erf by polynomials,
//                   permutes and fused multiply-adds, no loads).
// Both reproduce the scalar lookups' clamping. On x86-64 (FOOTPRINT_HAVE_LANES defined)
// they are compiled for AVX2 + FMA whatever the translation unit targets: code between
// FOOTPRINT_LANES_BEGIN and FOOTPRINT_LANES_END is, so a portable build carries the vector
// loops and calls them only where footprint::cpuHasLanes() (checked at run time); native
// builds (-march with AVX2) call them unconditionally. Elsewhere callers use the scalar
// lookups, which are exact too. The tests compare both paths with the tables.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define FOOTPRINT_HAVE_LANES 1
#include <immintrin.h>

#include <array>

#if defined(__clang__)
#define FOOTPRINT_LANES_BEGIN \
    _Pragma("clang attribute push(__attribute__((target(\"avx2,fma\"))), apply_to = function)")
#define FOOTPRINT_LANES_END _Pragma("clang attribute pop")
#else
#define FOOTPRINT_LANES_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2,fma\")")
#define FOOTPRINT_LANES_END _Pragma("GCC pop_options")
#endif

#include "footprint/footprint_poly.h"
#include "footprint/footprint_table.h"
#include "footprint/gaussian_slab.h"
#include "footprint/slab_table.h"

namespace footprint {

/// True when this CPU runs the AVX2 + FMA lanes (always, in a build that targets them).
inline bool cpuHasLanes() {
#if defined(__AVX2__) && defined(__FMA__)
    return true;
#else
    static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    return has;
#endif
}

FOOTPRINT_LANES_BEGIN

static_assert(sizeof(std::array<std::array<float, 8>, 8>) == 64 * sizeof(float),
              "the lanes read a polynomial's coefficient rows as one array");

class FootprintLanes {
  public:
    /// `poly` (optional) must approximate `table`; it is used instead of the table.
    FootprintLanes(const FootprintTable& table, const FootprintPoly* poly)
        : poly_(poly),
          data_(table.values_.data()),
          inv_(_mm256_set1_ps(table.invStep_)),
          last_(_mm256_set1_ps(float(table.resolution()))),
          coef_(poly ? poly->coefficients()[0].data() : nullptr),
          seg_(_mm256_set1_ps(poly ? poly->segmentScale() : 0.0f)),
          lastSeg_(_mm256_set1_ps(float(FootprintPoly::kSegments - 1))) {}
    /// fp(r2) for r2 >= 0; lanes at or beyond R^2 must be masked by the caller. Inlined
    /// always: a call would clobber every vector register the caller's loop holds.
    [[gnu::always_inline]] __m256 operator()(__m256 r2) const {
        if (poly_) {
            const __m256 s = _mm256_mul_ps(r2, seg_);
            const __m256 sf = _mm256_min_ps(_mm256_floor_ps(s), lastSeg_);
            const __m256i seg = _mm256_cvttps_epi32(sf);
            const __m256 u =
                _mm256_fmsub_ps(_mm256_set1_ps(2.0f), _mm256_sub_ps(s, sf), _mm256_set1_ps(1.0f));
            // u^k's coefficients of the 8 segments (read in place: the splatters make one
            // of these per splat, so the constructor copies nothing)
            auto a = [&](int k) {
                return _mm256_permutevar8x32_ps(
                    _mm256_loadu_ps(coef_ + FootprintPoly::kSegments * (7 - k)), seg);
            };
            const __m256 u2 = _mm256_mul_ps(u, u), u4 = _mm256_mul_ps(u2, u2);
            const __m256 q0 = _mm256_fmadd_ps(a(1), u, a(0)), q1 = _mm256_fmadd_ps(a(3), u, a(2));
            const __m256 q2 = _mm256_fmadd_ps(a(5), u, a(4)), q3 = _mm256_fmadd_ps(a(7), u, a(6));
            return _mm256_fmadd_ps(_mm256_fmadd_ps(q3, u2, q2), u4, _mm256_fmadd_ps(q1, u2, q0));
        }
        const __m256 t = _mm256_min_ps(_mm256_mul_ps(r2, inv_), last_);
        const __m256i i = _mm256_cvttps_epi32(t);
        const __m256 f = _mm256_sub_ps(t, _mm256_cvtepi32_ps(i));
        const __m256 v0 = _mm256_i32gather_ps(data_, i, 4);
        const __m256 v1 = _mm256_i32gather_ps(data_ + 1, i, 4);
        return _mm256_fmadd_ps(f, _mm256_sub_ps(v1, v0), v0);
    }

  private:
    const FootprintPoly* poly_;
    const float* data_;
    __m256 inv_, last_;
    const float* coef_;  // FootprintPoly::coefficients(), kMaxCoefficients rows of kSegments
    __m256 seg_, lastSeg_;
};

class FractionLanes {
  public:
    explicit FractionLanes(const SlabTable& t)
        : values_(t.values_.data()),
          invR_(_mm256_set1_ps(t.invR2Step_)),
          invZ_(_mm256_set1_ps(t.invZStep_)),
          zMin_(_mm256_set1_ps(t.zMin_)),
          nr_(_mm256_set1_ps(t.nrf_)),
          nz_(_mm256_set1_ps(t.nzf_)),
          stride_(_mm256_set1_epi32(t.stride_)) {}

    /// The radial part of a lookup, shared by every depth at the same r^2 (r2 >= 0).
    struct Radial {
        __m256i row;  ///< index of the grid row below r^2 (times the row stride)
        __m256 fr;    ///< fraction towards the next row
    };
    Radial radial(__m256 r2) const {
        const __m256 rr = _mm256_min_ps(_mm256_mul_ps(r2, invR_), nr_);
        const __m256i ri = _mm256_cvttps_epi32(rr);
        return {_mm256_mullo_epi32(ri, stride_), _mm256_sub_ps(rr, _mm256_cvtepi32_ps(ri))};
    }
    /// F(r^2, z) for the lanes' radial part and depths z (kernel units).
    __m256 operator()(const Radial& r, __m256 z) const {
        const __m256 zero = _mm256_setzero_ps();
        __m256 zz = _mm256_mul_ps(_mm256_sub_ps(z, zMin_), invZ_);
        zz = _mm256_min_ps(_mm256_max_ps(zz, zero), nz_);  // NaN -> 0 as fraction()
        const __m256i j = _mm256_cvttps_epi32(zz);
        const __m256 fz = _mm256_sub_ps(zz, _mm256_cvtepi32_ps(j));
        // The table interleaves rows i and i + 1, so a lane's four values are one 16-byte
        // load: [F(i, j) F(i + 1, j) F(i, j + 1) F(i + 1, j + 1)]. Eight loads and a 4 x 8
        // transpose beat four 8-lane float gathers (32 element reads) and four 4-lane
        // 64-bit gathers (16).
        alignas(32) int at[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(at), _mm256_add_epi32(r.row, j));
        auto cell = [&](int l, int h) {  // lanes l and h, in the low and high half
            return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(values_ + 2 * at[l])),
                                        _mm_loadu_ps(values_ + 2 * at[h]), 1);
        };
        const __m256 c0 = cell(0, 4), c1 = cell(1, 5), c2 = cell(2, 6), c3 = cell(3, 7);
        const __m256 u0 = _mm256_unpacklo_ps(c0, c1), u1 = _mm256_unpackhi_ps(c0, c1);
        const __m256 u2 = _mm256_unpacklo_ps(c2, c3), u3 = _mm256_unpackhi_ps(c2, c3);
        const __m256 p0 = _mm256_shuffle_ps(u0, u2, _MM_SHUFFLE(1, 0, 1, 0));
        const __m256 p2 = _mm256_shuffle_ps(u0, u2, _MM_SHUFFLE(3, 2, 3, 2));
        const __m256 p1 = _mm256_shuffle_ps(u1, u3, _MM_SHUFFLE(1, 0, 1, 0));
        const __m256 p3 = _mm256_shuffle_ps(u1, u3, _MM_SHUFFLE(3, 2, 3, 2));
        const __m256 a = _mm256_fmadd_ps(fz, _mm256_sub_ps(p1, p0), p0);
        const __m256 b = _mm256_fmadd_ps(fz, _mm256_sub_ps(p3, p2), p2);
        return _mm256_fmadd_ps(r.fr, _mm256_sub_ps(b, a), a);
    }

  private:
    const float* values_;  // SlabTable::values_ (rows interleaved in pairs)
    __m256 invR_, invZ_, zMin_, nr_, nz_;
    __m256i stride_;
};

class GaussianSlabLanes {
  public:
    /// Lanes of N P (the kernel's normalisation N times GaussianSlab's P), so that
    /// N P(r^2, L) is half the footprint fp(r^2).
    explicit GaussianSlabLanes(const GaussianSlab& g)
        : r2Max_(_mm256_set1_ps(g.r2Max_)),
          k_(_mm256_set1_ps(g.k_)),
          eR_(_mm256_set1_ps(g.eR_ * g.norm_)),
          eRk_(_mm256_set1_ps(g.eR_ * g.norm_ * g.k_)),
          alpha_(_mm256_set1_ps(g.alpha_ * g.norm_)),
          s_(_mm256_set1_ps(g.s_)),
          c3_(_mm256_set1_ps(g.c3_ * g.norm_)),
          xMax_(_mm256_set1_ps(g.xMax_)),
          seg_(_mm256_set1_ps(g.segScale_)),
          lastSeg_(_mm256_set1_ps(float(GaussianSlab::kSegments - 1))),
          coef_(g.c_[0].data()) {}
    /// The radial part, N times GaussianSlab::Radial's a and b, with the chord's square
    /// l2 = L^2 and pl = N P(r^2, L), which the caller gives as half the footprint fp(r^2)
    /// (from its table or polynomial: the sections then sum to exactly that footprint).
    struct Radial {
        __m256 a, b, l2, pl;
    };
    Radial radial(__m256 r2, __m256 halfFootprint) const {
        const __m256 zero = _mm256_setzero_ps();
        const __m256 r = _mm256_max_ps(r2, zero);
        Radial out;
        out.l2 = _mm256_max_ps(_mm256_sub_ps(r2Max_, r), zero);
        out.a = _mm256_mul_ps(alpha_, exp(_mm256_mul_ps(_mm256_sub_ps(zero, k_), r)));
        out.b = _mm256_fmadd_ps(eRk_, out.l2, eR_);
        out.pl = halfFootprint;
        return out;
    }
    /// N P(r^2, z) with z clamped to the chord [-L, L] (NaN -> -L).
    __m256 operator()(const Radial& r, __m256 z) const {
        const __m256 l = _mm256_sqrt_ps(r.l2);
        const __m256 zc = _mm256_min_ps(_mm256_max_ps(z, _mm256_sub_ps(_mm256_setzero_ps(), l)), l);
        return inside(r, zc, erf(_mm256_mul_ps(zc, s_)),
                      _mm256_mul_ps(c3_, _mm256_mul_ps(zc, _mm256_mul_ps(zc, zc))));
    }
    /// N P at a depth z inside the chord whose erf(z / (sigma sqrt 2)) is e and whose cubic
    /// term N e_R k z^3 / 3 is q: a e - b z + q.
    static __m256 inside(const Radial& r, __m256 z, __m256 e, __m256 q) {
        return _mm256_fmadd_ps(r.a, e, _mm256_fnmadd_ps(r.b, z, q));
    }
    /// GaussianSlab::erf, 8 lanes.
    __m256 erf(__m256 x) const {
        const __m256 sign = _mm256_and_ps(x, _mm256_set1_ps(-0.0f));
        const __m256 ax = _mm256_min_ps(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), x), xMax_);
        const __m256 t = _mm256_mul_ps(ax, seg_);
        const __m256 tf = _mm256_min_ps(_mm256_floor_ps(t), lastSeg_);
        const __m256i seg = _mm256_cvttps_epi32(tf);
        const __m256 u =
            _mm256_fmsub_ps(_mm256_set1_ps(2.0f), _mm256_sub_ps(t, tf), _mm256_set1_ps(1.0f));
        constexpr int S = GaussianSlab::kSegments;
        __m256 p = _mm256_permutevar8x32_ps(_mm256_loadu_ps(coef_), seg);
        for (int d = 1; d < GaussianSlab::kCoefficients; ++d)
            p = _mm256_fmadd_ps(p, u,
                                _mm256_permutevar8x32_ps(_mm256_loadu_ps(coef_ + S * d), seg));
        return _mm256_or_ps(p, sign);
    }
    /// N e_R k / 3, the cubic term's coefficient.
    __m256 cubic() const { return c3_; }
    /// e^x for x <= 0 (relative error < 2e-7; about 1e-38 below -87, where it stops).
    static __m256 exp(__m256 x) {
        x = _mm256_max_ps(x, _mm256_set1_ps(-87.0f));
        const __m256 n = _mm256_round_ps(_mm256_mul_ps(x, _mm256_set1_ps(1.44269504088896341f)),
                                         _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
        __m256 r = _mm256_fnmadd_ps(n, _mm256_set1_ps(0.693359375f), x);
        r = _mm256_fnmadd_ps(n, _mm256_set1_ps(-2.12194440e-4f), r);
        // e^r on |r| <= ln2 / 2: Taylor to degree 6 (remainder < 1.7e-7 relative).
        __m256 p = _mm256_set1_ps(1.0f / 720.0f);
        p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f / 120.0f));
        p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f / 24.0f));
        p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f / 6.0f));
        p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(0.5f));
        p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f));
        p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f));
        const __m256i e =
            _mm256_slli_epi32(_mm256_add_epi32(_mm256_cvtps_epi32(n), _mm256_set1_epi32(127)), 23);
        return _mm256_mul_ps(p, _mm256_castsi256_ps(e));
    }

  private:
    __m256 r2Max_, k_, eR_, eRk_, alpha_, s_, c3_, xMax_, seg_, lastSeg_;
    const float* coef_;  // GaussianSlab's erf coefficients, kCoefficients rows of kSegments
};

FOOTPRINT_LANES_END

}  // namespace footprint
#endif
