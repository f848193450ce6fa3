#pragma once
// Sheet buffers, shared by both splatters. A sheet accumulates, per pixel of one tile,
// the weighted sums of the kernel pieces that fall into it: optical depth and emission
// (dvr, pre-classified; 4 channels) or the density integral (post-classified dvr, mip,
// xray; 1 channel). The splatters differ only in the weight a kernel piece gets (its
// whole footprint, or its slab section) and in which sheet it falls into.
#include <algorithm>
#include <array>
#include <vector>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

#include "compositing.h"
#include "footprint/ellipse.h"
#include "footprint/footprint_table.h"
#include "footprint/slab_table.h"
#include "footprint/footprint_poly.h"
#include "splat/transfer.h"
#include "tile_binning.h"

namespace splat {

/// The transfer function tabulated over density for per-pixel post-classification:
/// extinction and colour at n uniformly spaced densities, linear interpolation between.
class TransferTable {
  public:
    TransferTable() = default;
    TransferTable(const TransferFunction& tf, int n = 4096);
    /// Extinction per world unit and (non-premultiplied) colour at density d.
    void lookup(float d, float& rho, float& r, float& g, float& b) const {
        float t = (d - lo_) * inv_;
        t = std::clamp(t, 0.0f, float(n_ - 1));
        const int i = std::min(int(t), n_ - 2);
        const float f = t - float(i);
        const float* a = &v_[std::size_t(i) * 4];
        rho = a[0] + f * (a[4] - a[0]);
        r = a[1] + f * (a[5] - a[1]);
        g = a[2] + f * (a[6] - a[2]);
        b = a[3] + f * (a[7] - a[3]);
    }

  private:
    float lo_ = 0, inv_ = 1;
    int n_ = 2;
    std::vector<float> v_;
};

/// How a sheet pixel becomes a compositing sample.
struct SheetModel {
    RenderMode mode = RenderMode::Dvr;
    Classification classification = Classification::Pre;
    const TransferTable* transfer = nullptr;  ///< post-classification
    int channels() const {
        return mode == RenderMode::Dvr && classification == Classification::Pre ? 4 : 1;
    }
};

template <int NCh>
class SheetBuffer {
  public:
    /// A sheet for the tile whose top-left pixel is (ox, oy) and size w x h. Rows are
    /// padded to a multiple of 8 floats so that vector loops may run past the tile edge.
    SheetBuffer(int ox, int oy, int w, int h)
        : ox_(ox),
          oy_(oy),
          w_(w),
          h_(h),
          stride_((w + 7) & ~7),
          plane_(std::size_t(stride_) * h + kPlanePad),
          v_(std::size_t(NCh) * plane_ + 8, 0.0f) {
        clearDirty();
    }

    bool dirty() const { return dx0_ <= dx1_; }

    /// Adds values[c] * weight(r2, dx, dy) to every pixel of `rect` (image coordinates,
    /// inside this tile), where (dx, dy) is the pixel centre's offset from the splat
    /// centre (sx, sy) and r2 the squared kernel-space distance of its ray. Returns the
    /// number of pixels visited.
    template <class Weight>
    int splat(const float (&values)[NCh], float sx, float sy,
              const footprint::EllipticalFootprint& e, const PixelRect& rect, Weight&& weight) {
        const int x0 = rect.x0 - ox_, x1 = rect.x1 - ox_, y0 = rect.y0 - oy_, y1 = rect.y1 - oy_;
        markDirty(x0, x1, y0, y1);
        const float fx0 = float(rect.x0) + 0.5f - sx;
        for (int y = y0; y <= y1; ++y) {
            const float dy = float(y + oy_) + 0.5f - sy;
            const float shift = e.beta * dy, gyy = e.gamma * dy * dy;
            float* row = &v_[std::size_t(y) * stride_];
            for (int x = x0; x <= x1; ++x) {
                const float dx = fx0 + float(x - x0);
                const float q = dx + shift;
                const float r2 = e.a * q * q + gyy;  // EllipticalFootprint::r2
                const float wgt = weight(r2, dx, dy);
                for (int c = 0; c < NCh; ++c) row[c * plane_ + x] += values[c] * wgt;
            }
        }
        return (x1 - x0 + 1) * (y1 - y0 + 1);
    }

    /// splat() with the whole footprint as the weight, fp(r2) * e.scale: the inner loop of
    /// the axis-aligned splatter, eight pixels at a time where AVX2 is available.
    /// With `poly` (accurate to footprint::FootprintPoly::kTolerance) the table is evaluated without
    /// gathers.
    int splatFootprint(const float (&values)[NCh], float sx, float sy,
                       const footprint::EllipticalFootprint& e, const PixelRect& rect,
                       const footprint::FootprintTable& table, const footprint::FootprintPoly* poly);

    /// splat() with a slab section as the weight: the kernel between the depths t0 and t1
    /// (world units along the ray, relative to the splat centre), in kernel units
    /// z = depthScale (t - (tx dx + ty dy)); fp(r2) (F(r2, z1) - F(r2, z0)) * e.scale.
    /// Scalar; the image-aligned splatter's vectorised loop is splatSections() below.
    int splatSection(const float (&values)[NCh], float sx, float sy,
                     const footprint::EllipticalFootprint& e, const PixelRect& rect,
                     const footprint::SlabTable& table, const footprint::FootprintPoly* poly, float t0,
                     float t1);

    /// Turns the dirty part of the sheet into samples composited into `acc`, clears it.
    /// `pathLength` is the world length of a ray's path through the sheet (for the mean
    /// density of post-classification and mip); `pathScale`, if given, scales it per pixel
    /// (perspective rays cross a sheet obliquely).
    void flush(TileAccumulator& acc, const SheetModel& model, float pathLength,
               const float* pathScale) {
        if (!dirty()) return;
        const int xe = std::min(dx1_, w_ - 1);
        for (int y = dy0_; y <= dy1_; ++y) {
            for (int x = dx0_; x <= xe; ++x) {
                const int p = y * w_ + x;
                const float* v = &v_[std::size_t(y) * stride_ + x];
                const float len = pathScale ? pathLength * pathScale[p] : pathLength;
                if constexpr (NCh == 4) {
                    acc.composite(
                        p, sampleFromOpticalDepth(v[0], v[plane_], v[2 * plane_], v[3 * plane_]));
                } else if (model.mode == RenderMode::Dvr) {
                    float rho, r, g, b;
                    model.transfer->lookup(v[0] / len, rho, r, g, b);
                    const float alpha = -std::expm1(-rho * len);
                    acc.composite(p, {alpha, r * alpha, g * alpha, b * alpha});
                } else if (model.mode == RenderMode::Mip) {
                    acc.maximum(p, v[0] / len);
                } else {
                    acc.add(p, v[0]);
                }
            }
            for (int c = 0; c < NCh; ++c) {
                float* row = &v_[c * plane_ + std::size_t(y) * stride_];
                std::fill(row + dx0_, row + dx1_ + 1, 0.0f);
            }
        }
        acc.updateOpacity(dx0_, dy0_, xe, dy1_);
        clearDirty();
    }

    /// Row y of channel c (tile-local), for the splatting loops below.
    float* row(int c, int y) { return &v_[c * plane_ + std::size_t(y) * stride_]; }
    int originX() const { return ox_; }
    int originY() const { return oy_; }
    /// Records that tile-local pixels [x0, x1] x [y0, y1] may have been written.
    void markDirty(int x0, int x1, int y0, int y1) {
        dx0_ = std::min(dx0_, x0);
        dx1_ = std::max(dx1_, x1);
        dy0_ = std::min(dy0_, y0);
        dy1_ = std::max(dy1_, y1);
    }

  private:
    void clearDirty() {
        dx0_ = dy0_ = 1 << 30;
        dx1_ = dy1_ = -1;
    }
    // Channel planes of a 32 x 32 tile would be exactly 4 KiB apart, and loads of one plane
    // would then falsely depend on stores to the plane before (4K aliasing): pad them.
    static constexpr std::size_t kPlanePad = 24;
    int ox_, oy_, w_, h_, stride_;
    std::size_t plane_;
    int dx0_, dy0_, dx1_, dy1_;
    std::vector<float> v_;  // NCh planes of stride x h
};

#if defined(__AVX2__) && defined(__FMA__)
/// fp(r2) for 8 lanes (r2 >= 0; lanes at or beyond R^2 are masked by the caller): the
/// piecewise polynomial when one is given (permutes pick each lane's segment, Estrin's
/// scheme evaluates it), else the table itself with two gathers.
class FootprintLanes {
  public:
    FootprintLanes(const footprint::FootprintTable& table, const footprint::FootprintPoly* poly)
        : poly_(poly),
          data_(table.data()),
          inv_(_mm256_set1_ps(table.invStep())),
          last_(_mm256_set1_ps(float(table.resolution()))),
          seg_(_mm256_set1_ps(poly ? poly->segmentScale() : 0.0f)),
          lastSeg_(_mm256_set1_ps(float(footprint::FootprintPoly::kSegments - 1))) {
        if (poly)
            for (int k = 0; k < footprint::FootprintPoly::kMaxCoefficients; ++k)
                coef_[k] = _mm256_loadu_ps(poly->coefficients()[k].data());
    }
    __m256 operator()(__m256 r2) const {
        if (poly_) {
            const __m256 s = _mm256_mul_ps(r2, seg_);
            const __m256 sf = _mm256_min_ps(_mm256_floor_ps(s), lastSeg_);
            const __m256i seg = _mm256_cvttps_epi32(sf);
            const __m256 u =
                _mm256_fmsub_ps(_mm256_set1_ps(2.0f), _mm256_sub_ps(s, sf), _mm256_set1_ps(1.0f));
            auto a = [&](int k) { return _mm256_permutevar8x32_ps(coef_[7 - k], seg); };  // u^k
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
    const footprint::FootprintPoly* poly_;
    const float* data_;
    __m256 inv_, last_, seg_, lastSeg_;
    __m256 coef_[footprint::FootprintPoly::kMaxCoefficients] = {};
};

template <int NCh>
int SheetBuffer<NCh>::splatFootprint(const float (&values)[NCh], float sx, float sy,
                                     const footprint::EllipticalFootprint& e, const PixelRect& rect,
                                     const footprint::FootprintTable& table,
                                     const footprint::FootprintPoly* poly) {
    const int x0 = rect.x0 - ox_, x1 = rect.x1 - ox_, y0 = rect.y0 - oy_, y1 = rect.y1 - oy_;
    markDirty(x0, x1, y0, y1);
    const __m256 lane = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256 va = _mm256_set1_ps(e.a), vScale = _mm256_set1_ps(e.scale);
    const __m256 vMax = _mm256_set1_ps(table.r2Max()), zero = _mm256_setzero_ps();
    const FootprintLanes footprintOf(table, poly);
    __m256 vv[NCh];
    for (int c = 0; c < NCh; ++c) vv[c] = _mm256_set1_ps(values[c]);
    for (int y = y0; y <= y1; ++y) {
        const float dy = float(y + oy_) + 0.5f - sy;
        // r^2 = a (dx + beta dy)^2 + gamma dy^2 (EllipticalFootprint::r2).
        const float gyy = e.gamma * dy * dy, shift = e.beta * dy;
        const __m256 vgyy = _mm256_set1_ps(gyy), vshift = _mm256_set1_ps(shift);
        const __m256 lastX = _mm256_set1_ps(float(x1) + 0.5f);
        const __m256 firstX = _mm256_set1_ps(float(x0) - 0.5f);
        float* row = &v_[std::size_t(y) * stride_];
        for (int x = x0 & ~7; x <= x1; x += 8) {
            const __m256 px = _mm256_add_ps(_mm256_set1_ps(float(x)), lane);
            const __m256 q =
                _mm256_add_ps(_mm256_add_ps(px, _mm256_set1_ps(float(ox_) + 0.5f - sx)), vshift);
            const __m256 r2 = _mm256_fmadd_ps(_mm256_mul_ps(va, q), q, vgyy);
            const __m256 inside =
                _mm256_and_ps(_mm256_cmp_ps(r2, vMax, _CMP_LT_OQ),
                              _mm256_and_ps(_mm256_cmp_ps(px, lastX, _CMP_LT_OQ),
                                            _mm256_cmp_ps(px, firstX, _CMP_GT_OQ)));
            const __m256 fp = footprintOf(_mm256_max_ps(r2, zero));
            const __m256 w = _mm256_and_ps(inside, _mm256_mul_ps(fp, vScale));
            for (int c = 0; c < NCh; ++c) {
                float* p = row + c * plane_ + x;
                _mm256_storeu_ps(p, _mm256_fmadd_ps(vv[c], w, _mm256_loadu_ps(p)));
            }
        }
    }
    return (x1 - x0 + 1) * (y1 - y0 + 1);
}


/// The sections of one kernel in n consecutive slabs at once, slab j between the depths
/// tb[j] and tb[j + 1] (world units along the ray, relative to the splat centre), each
/// added to sheets[j]. Sharing r^2, fp(r^2) and the fraction F(r^2, z) at every inner slab
/// boundary between the slabs halves the work of splatting slab by slab.
template <int NCh>
int splatSections(SheetBuffer<NCh>* const* sheets, int n, const float (&values)[NCh], float sx,
                  float sy, const footprint::EllipticalFootprint& e, const PixelRect& rect,
                  const footprint::SlabTable& table, const footprint::FootprintPoly* poly, const float* tb) {
    const footprint::FootprintTable& fpTable = table.footprint();
    const footprint::SlabTable::Grid grid = table.grid();
    const int ox = sheets[0]->originX(), oy = sheets[0]->originY();
    const int x0 = rect.x0 - ox, x1 = rect.x1 - ox, y0 = rect.y0 - oy, y1 = rect.y1 - oy;
    for (int j = 0; j < n; ++j) sheets[j]->markDirty(x0, x1, y0, y1);
    const __m256 lane = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7), zero = _mm256_setzero_ps();
    const __m256 signBit = _mm256_set1_ps(-0.0f);
    const __m256 va = _mm256_set1_ps(e.a), vScale = _mm256_set1_ps(e.scale);
    const __m256 vMax = _mm256_set1_ps(fpTable.r2Max());
    const FootprintLanes footprintOf(fpTable, poly);
    const __m256 gInvR = _mm256_set1_ps(grid.invR2Step), gInvZ = _mm256_set1_ps(grid.invZStep);
    const __m256 gZMin = _mm256_set1_ps(grid.zMin), gNr = _mm256_set1_ps(grid.nrf);
    const __m256 gNz = _mm256_set1_ps(grid.nzf);
    const __m256i gStride = _mm256_set1_epi32(grid.stride), ione = _mm256_set1_epi32(1);
    const __m256 vds = _mm256_set1_ps(e.depthScale), vtx = _mm256_set1_ps(e.tx);
    __m256 vv[NCh];
    for (int c = 0; c < NCh; ++c) vv[c] = _mm256_set1_ps(values[c]);
    auto fraction = [&](__m256i rowIndex, __m256 fr, __m256 z) {
        __m256 zz = _mm256_mul_ps(_mm256_sub_ps(z, gZMin), gInvZ);
        zz = _mm256_min_ps(_mm256_max_ps(zz, zero), gNz);  // NaN -> 0 as fraction()
        const __m256i j = _mm256_cvttps_epi32(zz);
        const __m256 fz = _mm256_sub_ps(zz, _mm256_cvtepi32_ps(j));
        const __m256i idx = _mm256_add_epi32(rowIndex, j);
        const __m256i idx2 = _mm256_add_epi32(idx, gStride);
        const __m256 p0 = _mm256_i32gather_ps(grid.values, idx, 4);
        const __m256 p1 = _mm256_i32gather_ps(grid.values, _mm256_add_epi32(idx, ione), 4);
        const __m256 p2 = _mm256_i32gather_ps(grid.values, idx2, 4);
        const __m256 p3 = _mm256_i32gather_ps(grid.values, _mm256_add_epi32(idx2, ione), 4);
        const __m256 a = _mm256_fmadd_ps(fz, _mm256_sub_ps(p1, p0), p0);
        const __m256 b = _mm256_fmadd_ps(fz, _mm256_sub_ps(p3, p2), p2);
        return _mm256_fmadd_ps(fr, _mm256_sub_ps(b, a), a);
    };
    for (int y = y0; y <= y1; ++y) {
        const float dy = float(y + oy) + 0.5f - sy;
        const __m256 vgyy = _mm256_set1_ps(e.gamma * dy * dy), vshift = _mm256_set1_ps(e.beta * dy);
        const __m256 vtyy = _mm256_set1_ps(e.ty * dy);
        const __m256 lastX = _mm256_set1_ps(float(x1) + 0.5f);
        for (int x = x0; x <= x1; x += 8) {
            const __m256 px = _mm256_add_ps(_mm256_set1_ps(float(x)), lane);
            const __m256 dx = _mm256_add_ps(px, _mm256_set1_ps(float(ox) + 0.5f - sx));
            const __m256 q = _mm256_add_ps(dx, vshift);
            const __m256 r2 = _mm256_max_ps(_mm256_fmadd_ps(_mm256_mul_ps(va, q), q, vgyy), zero);
            const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(r2, vMax, _CMP_LT_OQ),
                                                _mm256_cmp_ps(px, lastX, _CMP_LT_OQ));
            const __m256 weight = _mm256_and_ps(inside, _mm256_mul_ps(footprintOf(r2), vScale));
            const __m256 rr = _mm256_min_ps(_mm256_mul_ps(r2, gInvR), gNr);
            const __m256i ri = _mm256_cvttps_epi32(rr);
            const __m256 fr = _mm256_sub_ps(rr, _mm256_cvtepi32_ps(ri));
            const __m256i rowIndex = _mm256_mullo_epi32(ri, gStride);
            const __m256 tc = _mm256_fmadd_ps(vtx, dx, vtyy);
            auto depth = [&](int b) {
                return _mm256_mul_ps(vds, _mm256_sub_ps(_mm256_set1_ps(tb[b]), tc));
            };
            __m256 below = fraction(rowIndex, fr, depth(0));
            for (int j = 0; j < n; ++j) {
                const __m256 above = fraction(rowIndex, fr, depth(j + 1));
                // |F(above) - F(below)|: the boundaries run back to front when compositing is.
                const __m256 w =
                    _mm256_mul_ps(weight, _mm256_andnot_ps(signBit, _mm256_sub_ps(above, below)));
                below = above;
                for (int c = 0; c < NCh; ++c) {
                    float* p = sheets[j]->row(c, y) + x;
                    _mm256_storeu_ps(p, _mm256_fmadd_ps(vv[c], w, _mm256_loadu_ps(p)));
                }
            }
        }
    }
    return n * (x1 - x0 + 1) * (y1 - y0 + 1);
}
#else
template <int NCh>
int SheetBuffer<NCh>::splatFootprint(const float (&values)[NCh], float sx, float sy,
                                     const footprint::EllipticalFootprint& e, const PixelRect& rect,
                                     const footprint::FootprintTable& table,
                                     const footprint::FootprintPoly*) {
    // Without AVX2 the table's own lookup is as fast as the polynomial and exact.
    const float scale = e.scale;
    return splat(values, sx, sy, e, rect,
                 [&](float r2, float, float) { return table.lookup(r2) * scale; });
}


template <int NCh>
int splatSections(SheetBuffer<NCh>* const* sheets, int n, const float (&values)[NCh], float sx,
                  float sy, const footprint::EllipticalFootprint& e, const PixelRect& rect,
                  const footprint::SlabTable& table, const footprint::FootprintPoly* poly, const float* tb) {
    int visited = 0;
    for (int j = 0; j < n; ++j)
        visited += sheets[j]->splatSection(values, sx, sy, e, rect, table, poly,
                                           std::min(tb[j], tb[j + 1]), std::max(tb[j], tb[j + 1]));
    return visited;
}
#endif

/// Scalar slab section (any build; the vectorised loop is splatSections).
template <int NCh>
int SheetBuffer<NCh>::splatSection(const float (&values)[NCh], float sx, float sy,
                                   const footprint::EllipticalFootprint& e, const PixelRect& rect,
                                   const footprint::SlabTable& table, const footprint::FootprintPoly*,
                                   float t0, float t1) {
    const float ds = e.depthScale, tx = e.tx, ty = e.ty, scale = e.scale;
    return splat(values, sx, sy, e, rect, [&](float r2, float dx, float dy) {
        const float tc = tx * dx + ty * dy;
        return table.section(r2, ds * (t0 - tc), ds * (t1 - tc)) * scale;
    });
}


}  // namespace splat
