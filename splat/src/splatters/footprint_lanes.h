#pragma once
// The axis-aligned splatter's footprint loops (eight pixels per AVX2 group): a whole
// footprint fp(r^2) * scale (footprint/footprint_table.h), seen through the shared ellipse
// (footprint/ellipse.h), added to a tile's sheet. Where voxels are about a pixel wide
// (footprint boxes at most 4 pixels wide) two rows share one group; the sheet then holds the
// same values to the bit as with one row per group (a test compares both).
#include <cstddef>

#include "footprint/ellipse.h"
#include "footprint/footprint_table.h"
#include "footprint/lanes.h"
#include "frame/sheet_buffer.h"

#if defined(FOOTPRINT_HAVE_LANES)
#include <immintrin.h>

namespace splat {

FOOTPRINT_LANES_BEGIN
/// fp(r^2) for eight r^2 >= 0 from a footprint polynomial of degree <= 5 (lanes at or beyond
/// R^2 masked by the caller): footprint::FootprintLanes' evaluation without its terms of
/// degree 6 and 7, which are exact zeros there, so every value is the same to the bit and
/// a lookup costs two permutes and two fused multiply-adds less (the default Gaussian's
/// polynomial has degree 5).
class Degree5Lanes {
  public:
    explicit Degree5Lanes(const footprint::FootprintPoly& poly)
        : seg_(_mm256_set1_ps(poly.segmentScale())),
          lastSeg_(_mm256_set1_ps(float(footprint::FootprintPoly::kSegments - 1))) {
        for (int k = 0; k < 6; ++k)
            coef_[k] = _mm256_loadu_ps(
                poly.coefficients()[footprint::FootprintPoly::kMaxCoefficients - 1 - k].data());
    }
    static bool fits(const footprint::FootprintPoly& poly) {
        return footprint::FootprintPoly::kMaxCoefficients == 8 && poly.degree() <= 5;
    }
    __m256 operator()(__m256 r2) const {
        const __m256 s = _mm256_mul_ps(r2, seg_);
        const __m256 sf = _mm256_min_ps(_mm256_floor_ps(s), lastSeg_);
        const __m256i seg = _mm256_cvttps_epi32(sf);
        const __m256 u =
            _mm256_fmsub_ps(_mm256_set1_ps(2.0f), _mm256_sub_ps(s, sf), _mm256_set1_ps(1.0f));
        auto a = [&](int k) { return _mm256_permutevar8x32_ps(coef_[k], seg); };  // of u^k
        const __m256 u2 = _mm256_mul_ps(u, u), u4 = _mm256_mul_ps(u2, u2);
        const __m256 q0 = _mm256_fmadd_ps(a(1), u, a(0)), q1 = _mm256_fmadd_ps(a(3), u, a(2));
        const __m256 q2 = _mm256_fmadd_ps(a(5), u, a(4));
        return _mm256_fmadd_ps(q2, u4, _mm256_fmadd_ps(q1, u2, q0));
    }

  private:
    __m256 seg_, lastSeg_;
    __m256 coef_[6];  ///< coefficient of u^k of every segment
};

/// One footprint's constants for the vector loops below (tile-local pixel x of lane i is
/// x + i; r^2 = a (dx + beta dy)^2 + gamma dy^2, EllipticalFootprint::r2).
template <int NCh>
struct FootprintLaneSetup {
    __m256 va, vScale, vMax, zero, vOffset, vv[NCh];
    std::ptrdiff_t plane;  ///< floats between channel planes

    FootprintLaneSetup(SheetBuffer<NCh>& sheet, const float (&values)[NCh], float sx,
                       const footprint::EllipticalFootprint& e,
                       const footprint::FootprintTable& table)
        : va(_mm256_set1_ps(e.a)),
          vScale(_mm256_set1_ps(e.scale)),
          vMax(_mm256_set1_ps(table.r2Max())),
          zero(_mm256_setzero_ps()),
          vOffset(_mm256_set1_ps(float(sheet.originX()) + 0.5f - sx)),
          // Row pointers from plain locals: the stores could alias the sheet's members,
          // which the compiler would otherwise reload after every store.
          plane(NCh > 1 ? sheet.row(1, 0) - sheet.row(0, 0) : 0) {
        for (int c = 0; c < NCh; ++c) vv[c] = _mm256_set1_ps(values[c]);
    }
    /// The weights fp(r^2) * scale of the lanes at tile-local columns px, rows whose
    /// gamma dy^2 and beta dy are vgyy and vshift, zero outside the footprint or past
    /// column lastX - 0.5.
    template <class Footprint>
    __m256 weights(__m256 px, __m256 vgyy, __m256 vshift, __m256 lastX,
                   const Footprint& footprintOf) const {
        const __m256 q = _mm256_add_ps(_mm256_add_ps(px, vOffset), vshift);
        const __m256 r2 = _mm256_fmadd_ps(_mm256_mul_ps(va, q), q, vgyy);
        const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(r2, vMax, _CMP_LT_OQ),
                                            _mm256_cmp_ps(px, lastX, _CMP_LT_OQ));
        const __m256 fp = footprintOf(_mm256_max_ps(r2, zero));
        return _mm256_and_ps(inside, _mm256_mul_ps(fp, vScale));
    }
};

/// Row y of the footprint, pixels x0..x1 (tile-local), eight lanes at a time. Lanes start
/// at the box's first pixel, not at an 8-aligned one: a box up to 8 pixels wide is one
/// group per row wherever it lies (the lanes past x1 add zero to the row's padding or to
/// the next row; SheetBuffer pads the last row's end).
template <int NCh, class Footprint>
void splatFootprintRow(SheetBuffer<NCh>& sheet, const FootprintLaneSetup<NCh>& f, float dy,
                       const footprint::EllipticalFootprint& e, int y, int x0, int x1,
                       const Footprint& footprintOf) {
    const __m256 lane = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256 vgyy = _mm256_set1_ps(e.gamma * dy * dy), vshift = _mm256_set1_ps(e.beta * dy);
    const __m256 lastX = _mm256_set1_ps(float(x1) + 0.5f);
    float* const base = sheet.row(0, y);
    for (int x = x0; x <= x1; x += 8) {
        const __m256 w = f.weights(_mm256_add_ps(_mm256_set1_ps(float(x)), lane), vgyy, vshift,
                                   lastX, footprintOf);
        float* p = base + x;
        for (int c = 0; c < NCh; ++c, p += f.plane)
            _mm256_storeu_ps(p, _mm256_fmadd_ps(f.vv[c], w, _mm256_loadu_ps(p)));
    }
}

/// Rows y and y + 1 of a footprint at most 4 pixels wide (x0..x1, tile-local) in one group
/// of eight lanes: lanes 0-3 are row y, lanes 4-7 row y + 1. Every lane computes what
/// splatFootprintRow's lane of the same pixel computes, so the sheet holds the same values
/// to the bit, in half the groups where voxels are about a pixel wide.
template <int NCh, class Footprint>
void splatFootprintRowPair(SheetBuffer<NCh>& sheet, const FootprintLaneSetup<NCh>& f, float sy,
                           const footprint::EllipticalFootprint& e, int y, int x0, int x1,
                           const Footprint& footprintOf) {
    const int oy = sheet.originY();
    const float dy = float(y + oy) + 0.5f - sy, dy1 = float(y + 1 + oy) + 0.5f - sy;
    const __m256 vgyy =
        _mm256_setr_m128(_mm_set1_ps(e.gamma * dy * dy), _mm_set1_ps(e.gamma * dy1 * dy1));
    const __m256 vshift = _mm256_setr_m128(_mm_set1_ps(e.beta * dy), _mm_set1_ps(e.beta * dy1));
    const __m256 px =
        _mm256_add_ps(_mm256_set1_ps(float(x0)), _mm256_setr_ps(0, 1, 2, 3, 0, 1, 2, 3));
    const __m256 w = f.weights(px, vgyy, vshift, _mm256_set1_ps(float(x1) + 0.5f), footprintOf);
    float* p = sheet.row(0, y) + x0;
    float* q = sheet.row(0, y + 1) + x0;
    for (int c = 0; c < NCh; ++c, p += f.plane, q += f.plane)
        _mm256_storeu2_m128(q, p, _mm256_fmadd_ps(f.vv[c], w, _mm256_loadu2_m128(q, p)));
}

/// Adds values * fp(r^2) * e.scale, the whole footprint, to the pixels of `rect`: eight
/// pixels at a time where AVX2 is available (fp from `footprintOf`: FootprintLanes or
/// Degree5Lanes); a box at most 4 pixels wide takes two rows per group unless `pairRows` is
/// false.
template <int NCh, class Footprint>
int splatFootprintLanes(SheetBuffer<NCh>& sheet, const float (&values)[NCh], float sx, float sy,
                        const footprint::EllipticalFootprint& e, const PixelRect& rect,
                        const footprint::FootprintTable& table, const Footprint& footprintOf,
                        bool pairRows = true) {
    const int ox = sheet.originX(), oy = sheet.originY();
    const int x0 = rect.x0 - ox, x1 = rect.x1 - ox, y0 = rect.y0 - oy, y1 = rect.y1 - oy;
    sheet.markDirty(x0, x1, y0, y1);
    const FootprintLaneSetup<NCh> f(sheet, values, sx, e, table);
    const bool narrow = pairRows && x1 - x0 < 4;
    int y = y0;
    for (; narrow && y < y1; y += 2) splatFootprintRowPair(sheet, f, sy, e, y, x0, x1, footprintOf);
    for (; y <= y1; ++y)
        splatFootprintRow(sheet, f, float(y + oy) + 0.5f - sy, e, y, x0, x1, footprintOf);
    return (x1 - x0 + 1) * (y1 - y0 + 1);
}

/// splatFootprintLanes with the footprint polynomial (Degree5Lanes where it fits) or table.
template <int NCh>
int splatFootprintVector(SheetBuffer<NCh>& sheet, const float (&values)[NCh], float sx, float sy,
                         const footprint::EllipticalFootprint& e, const PixelRect& rect,
                         const footprint::FootprintTable& table,
                         const footprint::FootprintPoly* poly) {
    if (poly && Degree5Lanes::fits(*poly))
        return splatFootprintLanes(sheet, values, sx, sy, e, rect, table, Degree5Lanes(*poly));
    return splatFootprintLanes(sheet, values, sx, sy, e, rect, table,
                               footprint::FootprintLanes(table, poly));
}
FOOTPRINT_LANES_END

}  // namespace splat
#endif
