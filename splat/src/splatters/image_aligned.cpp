// The image-aligned sheet-buffer splatter (K. Mueller and R. Crawfis, "Eliminating popping
// artifacts in sheet buffer-based splatting", IEEE Visualization 1998): sheets are slabs
// of thickness T parallel to the image plane; every kernel adds to each slab it crosses the
// section of its footprint between the slab's two depths, C(r, z1) - C(r, z0) from the
// cumulative slab table (footprint/slab_table.h). The sheets never change orientation, so
// there is no popping; the cost grows as T shrinks.
//
// Splats are visited through depth buckets: sorted by the first slab they touch (last
// slab for back-to-front). The tile sweep keeps a ring of sheets as deep as a kernel is
// thick: when it reaches a splat, the splat's sections are added to every slab it crosses
// at once (sharing r^2, the footprint and the section boundaries between them).
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "footprint/lanes.h"
#include "footprint/slab_table.h"
#include "splat/error.h"
#include "splatters/splatter.h"

namespace splat {

namespace {

/// Most slabs a frame may have: beyond this, the depth range is absurd for the slab
/// thickness (e.g. an extreme spacing ratio), and the buckets would not fit in memory.
constexpr double kMaxSlabs = double(1 << 24);

/// Most slabs one kernel may span (the slab thickness is at least 1e-3 voxels).
constexpr int kMaxSpan = 8192;

/// The boundaries a row of a kernel's slabs must evaluate: those whose depth over the row
/// is beyond the kernel on the near side (`front(b)`) or the far side (`back(b)`) take a
/// constant, and since the depths are monotone in b (ascending front to back, descending back
/// to front) they are a prefix [0, pre) and a suffix [suf, n]; the row visits slabs
/// [max(pre - 1, 0), min(suf, n)).
struct SlabRange {
    int pre, suf, jBegin, jEnd;
};
template <class Front, class Back>
[[gnu::always_inline]] inline SlabRange slabRange(int n, bool ascending, Front front, Back back) {
    int pre = 0, suf = n + 1;
    if (ascending) {
        while (pre <= n && front(pre)) ++pre;
        while (suf > pre && back(suf - 1)) --suf;
    } else {
        while (pre <= n && back(pre)) ++pre;
        while (suf > pre && front(suf - 1)) --suf;
    }
    return {pre, suf, std::max(pre - 1, 0), std::min(suf, n)};
}

/// Where the vector loops write: channel c of row y of sheet j starts at
/// origin[j] + y stride + c plane. The sheets a splat is cut into all have the tile's size
/// (one ring or group of sheets made alike), so stride and plane are the same for every
/// sheet and are read once per splat, not per row and sheet.
struct SheetRows {
    float* origin[kMaxSpan];
    std::ptrdiff_t stride, plane;
};
template <int NCh>
void sheetRows(SheetBuffer<NCh>* const* sheets, int n, SheetRows& out) {
    out.stride = sheets[0]->row(0, 1) - sheets[0]->row(0, 0);
    out.plane = NCh > 1 ? sheets[0]->row(1, 0) - sheets[0]->row(0, 0) : 0;
    for (int j = 0; j < n; ++j) {
        out.origin[j] = sheets[j]->row(0, 0);
        if (sheets[j]->row(0, 1) - out.origin[j] != out.stride ||
            (NCh > 1 && sheets[j]->row(1, 0) - out.origin[j] != out.plane))
            throw std::logic_error("image-aligned splatter: a splat's sheets differ in size");
    }
}

/// The sections of one kernel in n consecutive slabs at once, slab j between the depths
/// tb[j] and tb[j + 1] (world units along the ray, relative to the splat centre), each added
/// to sheets[j]. Sharing r^2, fp(r^2) and the fraction F(r^2, z) at every inner slab
/// boundary between the slabs halves the work of splatting slab by slab.
#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
/// Adds one 8-pixel group of a kernel's sections to the rows of slabs jBegin .. jEnd - 1: slab
/// j gets values * scale * |at(j + 1) - at(j)|, at(b) the kernel's cumulative part (fraction
/// or N P) at boundary b (the boundaries run back to front when compositing is). add(q, v, w)
/// adds v * w to a channel's row at q (addRow, or addTwoRows for two rows in one vector).
template <int NCh, class At, class Add>
[[gnu::always_inline]] inline void addSections(const SheetRows& rows, std::ptrdiff_t at0,
                                               int jBegin, int jEnd, __m256 scale,
                                               const __m256 (&vv)[NCh], At at, Add add) {
    const __m256 signBit = _mm256_set1_ps(-0.0f);
    __m256 below = at(jBegin);
    for (int j = jBegin; j < jEnd; ++j) {
        const __m256 above = at(j + 1);
        const __m256 w =
            _mm256_mul_ps(scale, _mm256_andnot_ps(signBit, _mm256_sub_ps(above, below)));
        below = above;
        float* const p = rows.origin[j] + at0;
        for (int c = 0; c < NCh; ++c) add(p + c * rows.plane, vv[c], w);
    }
}

/// The 8 lanes of one row at q.
[[gnu::always_inline]] inline void addRow(float* q, __m256 v, __m256 w) {
    _mm256_storeu_ps(q, _mm256_fmadd_ps(v, w, _mm256_loadu_ps(q)));
}

/// Lanes 0-3 at q and, if `both`, lanes 4-7 at q + stride (the row below).
struct AddTwoRows {
    std::ptrdiff_t stride;
    bool both;
    [[gnu::always_inline]] void operator()(float* q, __m256 v, __m256 w) const {
        float* const below = q + stride;
        if (both) {
            _mm256_storeu2_m128(below, q, _mm256_fmadd_ps(v, w, _mm256_loadu2_m128(below, q)));
        } else {
            _mm_storeu_ps(q, _mm_fmadd_ps(_mm256_castps256_ps128(v), _mm256_castps256_ps128(w),
                                          _mm_loadu_ps(q)));
        }
    }
};

template <int NCh>
int splatSectionsLanes(SheetBuffer<NCh>* const* sheets, int n, const float (&values)[NCh], float sx,
                       float sy, const footprint::EllipticalFootprint& e, const PixelRect& rect,
                       const footprint::SlabTable& table, const footprint::FootprintPoly* poly,
                       const float* tb) {
    const footprint::FootprintTable& fpTable = table.footprint();
    const int ox = sheets[0]->originX(), oy = sheets[0]->originY();
    const int x0 = rect.x0 - ox, x1 = rect.x1 - ox, y0 = rect.y0 - oy, y1 = rect.y1 - oy;
    for (int j = 0; j < n; ++j) sheets[j]->markDirty(x0, x1, y0, y1);
    const __m256 lane = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7), vZero = _mm256_setzero_ps();
    const __m256 vOne = _mm256_set1_ps(1.0f);
    const __m256 va = _mm256_set1_ps(e.a), vScale = _mm256_set1_ps(e.scale);
    const __m256 vMax = _mm256_set1_ps(fpTable.r2Max());
    const footprint::FootprintLanes footprintOf(fpTable, poly);
    const footprint::FractionLanes fraction(table);
    const __m256 vds = _mm256_set1_ps(e.depthScale), vtx = _mm256_set1_ps(e.tx);
    __m256 vv[NCh];
    for (int c = 0; c < NCh; ++c) vv[c] = _mm256_set1_ps(values[c]);
    // Per row, F at boundary b is the constant 0 or 1 where the boundary's depth over the
    // row lies beyond the table's saturation bounds at the row's smallest r^2, and must be
    // looked up elsewhere. The boundaries' depths are monotone in b (ascending front to
    // back, descending back to front), so the constant ones are a prefix [0, pre) and a
    // suffix [suf, n] (front to back F = 0 before the kernel and 1 behind it; back to front
    // the reverse): a row visits only slabs [pre - 1, suf), the others' sections are zero.
    const bool ascending = tb[n] > tb[0];
    const __m256 vPre = ascending ? vZero : vOne, vSuf = ascending ? vOne : vZero;
    SheetRows rows;
    sheetRows(sheets, n, rows);
    for (int y = y0; y <= y1; ++y) {
        const float dy = float(y + oy) + 0.5f - sy;
        const float gyy = e.gamma * dy * dy;     // the row's smallest r^2 (every lane's r^2 >= it)
        if (!(gyy < fpTable.r2Max())) continue;  // the whole row is outside the ellipse
        const footprint::SlabTable::Saturation sat = table.saturation(gyy);
        // Depth of the rays' closest approach along the row: tc = tx dx + ty dy, linear in dx.
        const float dxA = float(x0 + ox) + 0.5f - sx, dxB = float(x1 + ox) + 0.5f - sx;
        const float tcA = e.tx * dxA + e.ty * dy, tcB = e.tx * dxB + e.ty * dy;
        const float tcLo = std::min(tcA, tcB), tcHi = std::max(tcA, tcB);
        // z(b) over the row's pixels lies in [zLo(b), zHi(b)].
        auto zero = [&](int b) { return e.depthScale * (tb[b] - tcLo) <= sat.zeroBelow; };
        auto one = [&](int b) { return e.depthScale * (tb[b] - tcHi) >= sat.oneAbove; };
        const SlabRange range = slabRange(n, ascending, zero, one);
        const int pre = range.pre, suf = range.suf, jBegin = range.jBegin, jEnd = range.jEnd;
        if (jBegin >= jEnd) continue;
        const std::ptrdiff_t rowAt = std::ptrdiff_t(y) * rows.stride;
        const __m256 vgyy = _mm256_set1_ps(gyy), vshift = _mm256_set1_ps(e.beta * dy);
        const __m256 vtyy = _mm256_set1_ps(e.ty * dy);
        const __m256 lastX = _mm256_set1_ps(float(x1) + 0.5f);
        for (int x = x0; x <= x1; x += 8) {
            const __m256 px = _mm256_add_ps(_mm256_set1_ps(float(x)), lane);
            const __m256 dx = _mm256_add_ps(px, _mm256_set1_ps(float(ox) + 0.5f - sx));
            const __m256 q = _mm256_add_ps(dx, vshift);
            const __m256 r2 = _mm256_max_ps(_mm256_fmadd_ps(_mm256_mul_ps(va, q), q, vgyy), vZero);
            const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(r2, vMax, _CMP_LT_OQ),
                                                _mm256_cmp_ps(px, lastX, _CMP_LT_OQ));
            const __m256 weight = _mm256_and_ps(inside, _mm256_mul_ps(footprintOf(r2), vScale));
            const footprint::FractionLanes::Radial radial = fraction.radial(r2);
            const __m256 tc = _mm256_fmadd_ps(vtx, dx, vtyy);
            // F at boundary b: z = depthScale (t - tc) in kernel units, looked up only where
            // the row is not saturated there.
            auto fractionAt = [&](int b) {
                if (b < pre) return vPre;
                if (b >= suf) return vSuf;
                return fraction(radial,
                                _mm256_mul_ps(vds, _mm256_sub_ps(_mm256_set1_ps(tb[b]), tc)));
            };
            addSections(rows, rowAt + x, jBegin, jEnd, weight, vv, fractionAt, addRow);
        }
    }
    return n * (x1 - x0 + 1) * (y1 - y0 + 1);
}

/// Most boundaries of the Flat closed-form path (splatSectionsClosedLanes); kernels
/// crossing more slabs take the general one.
constexpr int kMaxFlat = 64;

/// The Flat path's terms of one splat's boundaries (their depths are the same for every
/// pixel): z, z^2, erf(z / (sigma sqrt 2)) and the cubic term, and the sign bit of N P
/// beyond the chord on boundary b's side (-fp / 2 before the kernel's centre, +fp / 2
/// behind it).
struct FlatBoundaries {
    alignas(32) float z[kMaxFlat + 8], zz[kMaxFlat + 8], e[kMaxFlat + 8], q[kMaxFlat + 8],
        neg[kMaxFlat + 8];

    /// The n + 1 boundaries tb (n < kMaxFlat), 8 at a time.
    void compute(const float* tb, int n, float depthScale, const footprint::GaussianSlab& slab,
                 const footprint::GaussianSlabLanes& section) {
        for (int b = 0; b <= n; ++b) {
            z[b] = depthScale * tb[b];
            neg[b] = z[b] > 0.0f ? 0.0f : -0.0f;
        }
        for (int b = n + 1; b % 8; ++b) z[b] = 0.0f;
        const __m256 vs = _mm256_set1_ps(slab.erfScale());
        for (int b = 0; b <= n; b += 8) {
            const __m256 vz = _mm256_load_ps(z + b), vzz = _mm256_mul_ps(vz, vz);
            _mm256_store_ps(zz + b, vzz);
            _mm256_store_ps(e + b, section.erf(_mm256_mul_ps(vz, vs)));
            _mm256_store_ps(q + b, _mm256_mul_ps(section.cubic(), _mm256_mul_ps(vzz, vz)));
        }
    }

    /// N P at boundary b for the lanes' radial part: inside the chord a erf(z) - b z + q,
    /// beyond it `plus` (fp / 2) with the boundary's sign.
    [[gnu::always_inline]] __m256 at(const footprint::GaussianSlabLanes::Radial& radial,
                                     __m256 plus, int b) const {
        const __m256 in = _mm256_cmp_ps(radial.l2, _mm256_broadcast_ss(zz + b), _CMP_GT_OQ);
        const __m256 p = footprint::GaussianSlabLanes::inside(radial, _mm256_broadcast_ss(z + b),
                                                              _mm256_broadcast_ss(e + b),
                                                              _mm256_broadcast_ss(q + b));
        const __m256 beyond = _mm256_xor_ps(plus, _mm256_broadcast_ss(neg + b));
        return _mm256_blendv_ps(beyond, p, in);
    }
};

/// The radial part of N P for 8 pixels at offsets (dx, dy) from the splat centre whose rays
/// pass at r^2 = a (dx + beta dy)^2 + gamma dy^2 (shift = beta dy, gyy = gamma dy^2) and
/// half the footprint: pl = fp / 2, 0 (and the chord 0) outside the kernel and where `keep`
/// is clear.
struct RadialLanes {
    const footprint::FootprintLanes& footprintOf;
    const footprint::GaussianSlabLanes& section;
    __m256 a, r2Max;

    [[gnu::always_inline]] footprint::GaussianSlabLanes::Radial operator()(__m256 dx, __m256 shift,
                                                                           __m256 gyy,
                                                                           __m256 keep) const {
        const __m256 q = _mm256_add_ps(dx, shift);
        const __m256 r2 =
            _mm256_max_ps(_mm256_fmadd_ps(_mm256_mul_ps(a, q), q, gyy), _mm256_setzero_ps());
        const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(r2, r2Max, _CMP_LT_OQ), keep);
        footprint::GaussianSlabLanes::Radial radial = section.radial(
            r2, _mm256_and_ps(inside, _mm256_mul_ps(footprintOf(r2), _mm256_set1_ps(0.5f))));
        radial.l2 = _mm256_and_ps(inside, radial.l2);
        return radial;
    }
};

/// splatSectionsLanes with the kernel's closed form (footprint/gaussian_slab.h) instead of
/// the table's fraction: per pixel the radial part of N P (exp, and half the footprint from
/// the same table or polynomial as the axis-aligned splatter, so that the sections sum to
/// it), per boundary N P(z) and the section scale |N P(above) - N P(below)|. Flat: the
/// boundaries' depths are the same for every pixel (tx = ty = 0), so N P at a boundary
/// inside the chord is a erf(z) - b z + q with erf(z), z and q per splat, and +-fp / 2
/// outside it; no erf per pixel.
template <int NCh, bool Flat>
int splatSectionsClosedLanes(SheetBuffer<NCh>* const* sheets, int n, const float (&values)[NCh],
                             float sx, float sy, const footprint::EllipticalFootprint& e,
                             const PixelRect& rect, const footprint::FootprintTable& fpTable,
                             const footprint::GaussianSlab& slab,
                             const footprint::FootprintPoly* poly, const float* tb) {
    const int ox = sheets[0]->originX(), oy = sheets[0]->originY();
    const int x0 = rect.x0 - ox, x1 = rect.x1 - ox, y0 = rect.y0 - oy, y1 = rect.y1 - oy;
    for (int j = 0; j < n; ++j) sheets[j]->markDirty(x0, x1, y0, y1);
    const __m256 lane = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7), vZero = _mm256_setzero_ps();
    const __m256 vScale = _mm256_set1_ps(e.scale);
    const footprint::FootprintLanes footprintOf(fpTable, poly);
    const footprint::GaussianSlabLanes section(slab);
    const RadialLanes radialOf{footprintOf, section, _mm256_set1_ps(e.a),
                               _mm256_set1_ps(fpTable.r2Max())};
    const __m256 vds = _mm256_set1_ps(e.depthScale), vtx = _mm256_set1_ps(e.tx);
    __m256 vv[NCh];
    for (int c = 0; c < NCh; ++c) vv[c] = _mm256_set1_ps(values[c]);
    FlatBoundaries flat;
    if constexpr (Flat) flat.compute(tb, n, e.depthScale, slab, section);
    // As splatSectionsLanes: per row, the boundaries before the kernel's chord at the row's
    // smallest r^2 (N P = -fp / 2 front to back) and behind it (+fp / 2) are a prefix and
    // a suffix.
    const bool ascending = tb[n] > tb[0];
    SheetRows rows;
    sheetRows(sheets, n, rows);
    for (int y = y0; y <= y1; ++y) {
        const float dy = float(y + oy) + 0.5f - sy;
        const float gyy = e.gamma * dy * dy;
        if (!(gyy < fpTable.r2Max())) continue;
        const float chord = std::sqrt(std::max(slab.r2Max() - gyy, 0.0f));
        const float dxA = float(x0 + ox) + 0.5f - sx, dxB = float(x1 + ox) + 0.5f - sx;
        const float tcA = e.tx * dxA + e.ty * dy, tcB = e.tx * dxB + e.ty * dy;
        const float tcLo = std::min(tcA, tcB), tcHi = std::max(tcA, tcB);
        auto before = [&](int b) { return e.depthScale * (tb[b] - tcLo) <= -chord; };
        auto behind = [&](int b) { return e.depthScale * (tb[b] - tcHi) >= chord; };
        const SlabRange range = slabRange(n, ascending, before, behind);
        const int pre = range.pre, suf = range.suf, jBegin = range.jBegin, jEnd = range.jEnd;
        if (jBegin >= jEnd) continue;
        const std::ptrdiff_t rowAt = std::ptrdiff_t(y) * rows.stride;
        const __m256 vgyy = _mm256_set1_ps(gyy), vshift = _mm256_set1_ps(e.beta * dy);
        const __m256 vtyy = _mm256_set1_ps(e.ty * dy);
        const __m256 lastX = _mm256_set1_ps(float(x1) + 0.5f);
        for (int x = x0; x <= x1; x += 8) {
            const __m256 px = _mm256_add_ps(_mm256_set1_ps(float(x)), lane);
            const __m256 dx = _mm256_add_ps(px, _mm256_set1_ps(float(ox) + 0.5f - sx));
            // Outside the kernel (and beyond the rectangle) the chord and fp are 0: so is N P.
            const footprint::GaussianSlabLanes::Radial radial =
                radialOf(dx, vshift, vgyy, _mm256_cmp_ps(px, lastX, _CMP_LT_OQ));
            const __m256 plus = radial.pl, minus = _mm256_sub_ps(vZero, radial.pl);
            const __m256 vPre = ascending ? minus : plus, vSuf = ascending ? plus : minus;
            const __m256 tc = _mm256_fmadd_ps(vtx, dx, vtyy);
            auto pAt = [&](int b) {
                if (b < pre) return vPre;
                if (b >= suf) return vSuf;
                if constexpr (Flat) {
                    return flat.at(radial, plus, b);
                } else {
                    return section(radial,
                                   _mm256_mul_ps(vds, _mm256_sub_ps(_mm256_set1_ps(tb[b]), tc)));
                }
            };
            addSections(rows, rowAt + x, jBegin, jEnd, vScale, vv, pAt, addRow);
        }
    }
    return n * (x1 - x0 + 1) * (y1 - y0 + 1);
}
/// One row's part of a paired group: its offset dy from the splat centre, gamma dy^2, and
/// the prefix and suffix of constant boundaries (SlabRange; pre = suf = n + 1, every
/// boundary before the kernel, for a row outside it or past the rectangle).
struct PairedRow {
    float dy, gyy;
    SlabRange range;
};

/// The Flat path (splatSectionsClosedLanes) for rectangles at most 4 pixels wide, as a
/// kernel's rows are at small image sizes or where a tile's edge cuts it: rows y and y + 1
/// share one vector (lanes 0-3 and 4-7) instead of each filling 8 lanes with at most 4
/// pixels. Each lane computes what splatSectionsClosedLanes computes for its pixel, and a
/// row's boundaries outside its own range take that row's constants, so the sheets receive
/// the same sums bit for bit.
template <int NCh>
int splatSectionsPairedLanes(SheetBuffer<NCh>* const* sheets, int n, const float (&values)[NCh],
                             float sx, float sy, const footprint::EllipticalFootprint& e,
                             const PixelRect& rect, const footprint::FootprintTable& fpTable,
                             const footprint::GaussianSlab& slab,
                             const footprint::FootprintPoly* poly, const float* tb) {
    const int ox = sheets[0]->originX(), oy = sheets[0]->originY();
    const int x0 = rect.x0 - ox, x1 = rect.x1 - ox, y0 = rect.y0 - oy, y1 = rect.y1 - oy;
    for (int j = 0; j < n; ++j) sheets[j]->markDirty(x0, x1, y0, y1);
    const footprint::FootprintLanes footprintOf(fpTable, poly);
    const footprint::GaussianSlabLanes section(slab);
    const RadialLanes radialOf{footprintOf, section, _mm256_set1_ps(e.a),
                               _mm256_set1_ps(fpTable.r2Max())};
    const __m256 vScale = _mm256_set1_ps(e.scale), vZero = _mm256_setzero_ps();
    const __m256 px =
        _mm256_add_ps(_mm256_set1_ps(float(x0)), _mm256_setr_ps(0, 1, 2, 3, 0, 1, 2, 3));
    const __m256 dx = _mm256_add_ps(px, _mm256_set1_ps(float(ox) + 0.5f - sx));
    const __m256 inRect = _mm256_cmp_ps(px, _mm256_set1_ps(float(x1) + 0.5f), _CMP_LT_OQ);
    const __m256 lowHalf = _mm256_castsi256_ps(_mm256_setr_epi32(-1, -1, -1, -1, 0, 0, 0, 0));
    const __m256 highHalf = _mm256_castsi256_ps(_mm256_setr_epi32(0, 0, 0, 0, -1, -1, -1, -1));
    __m256 vv[NCh];
    for (int c = 0; c < NCh; ++c) vv[c] = _mm256_set1_ps(values[c]);
    FlatBoundaries flat;
    flat.compute(tb, n, e.depthScale, slab, section);
    const bool ascending = tb[n] > tb[0];
    SheetRows rows;
    sheetRows(sheets, n, rows);
    // As splatSectionsClosedLanes' rows (the depths do not depend on the pixel).
    auto rowOf = [&](int y) {
        PairedRow r;
        r.dy = float(y + oy) + 0.5f - sy;
        r.gyy = e.gamma * r.dy * r.dy;
        r.range = {n + 1, n + 1, n, 0};  // (an empty range that leaves the other row's)
        if (y > y1 || !(r.gyy < fpTable.r2Max())) return r;
        const float chord = std::sqrt(std::max(slab.r2Max() - r.gyy, 0.0f));
        const float dxA = float(x0 + ox) + 0.5f - sx, dxB = float(x1 + ox) + 0.5f - sx;
        const float tcA = e.tx * dxA + e.ty * r.dy, tcB = e.tx * dxB + e.ty * r.dy;
        const float tcLo = std::min(tcA, tcB), tcHi = std::max(tcA, tcB);
        auto before = [&](int b) { return e.depthScale * (tb[b] - tcLo) <= -chord; };
        auto behind = [&](int b) { return e.depthScale * (tb[b] - tcHi) >= chord; };
        r.range = slabRange(n, ascending, before, behind);
        return r;
    };
    for (int y = y0; y <= y1; y += 2) {
        const PairedRow a = rowOf(y), b = rowOf(y + 1);
        const int jBegin = std::min(a.range.jBegin, b.range.jBegin);
        const int jEnd = std::max(a.range.jEnd, b.range.jEnd);
        if (jBegin >= jEnd) continue;
        const __m256 shift =
            _mm256_setr_m128(_mm_set1_ps(e.beta * a.dy), _mm_set1_ps(e.beta * b.dy));
        const __m256 gyy = _mm256_setr_m128(_mm_set1_ps(a.gyy), _mm_set1_ps(b.gyy));
        const footprint::GaussianSlabLanes::Radial radial = radialOf(dx, shift, gyy, inRect);
        const __m256 plus = radial.pl, minus = _mm256_sub_ps(vZero, radial.pl);
        const __m256 vPre = ascending ? minus : plus, vSuf = ascending ? plus : minus;
        const int preLo = std::min(a.range.pre, b.range.pre),
                  preHi = std::max(a.range.pre, b.range.pre);
        const int sufLo = std::min(a.range.suf, b.range.suf),
                  sufHi = std::max(a.range.suf, b.range.suf);
        // The half whose row has boundary k before (after) the kernel: its constant.
        auto half = [&](bool inA, bool inB) {
            return inA ? (inB ? _mm256_castsi256_ps(_mm256_set1_epi32(-1)) : lowHalf) : highHalf;
        };
        auto pAt = [&](int k) {
            if (k < preLo) return vPre;
            if (k >= sufHi) return vSuf;
            __m256 p = flat.at(radial, plus, k);
            if (k < preHi) p = _mm256_blendv_ps(p, vPre, half(k < a.range.pre, k < b.range.pre));
            if (k >= sufLo) p = _mm256_blendv_ps(p, vSuf, half(k >= a.range.suf, k >= b.range.suf));
            return p;
        };
        addSections(rows, std::ptrdiff_t(y) * rows.stride + x0, jBegin, jEnd, vScale, vv, pAt,
                    AddTwoRows{rows.stride, y < y1});
    }
    return n * (x1 - x0 + 1) * (y1 - y0 + 1);
}
FOOTPRINT_LANES_END
#endif

template <int NCh>
int splatSectionsScalar(SheetBuffer<NCh>* const* sheets, int n, const float (&values)[NCh],
                        float sx, float sy, const footprint::EllipticalFootprint& e,
                        const PixelRect& rect, const footprint::SlabTable& table,
                        const footprint::FootprintPoly*, const float* tb) {
    int visited = 0;
    const float ds = e.depthScale, tx = e.tx, ty = e.ty, scale = e.scale;
    const footprint::GaussianSlab* closed = table.closedForm();
    const footprint::FootprintTable& fp = table.footprint();
    for (int j = 0; j < n; ++j) {
        const float t0 = std::min(tb[j], tb[j + 1]), t1 = std::max(tb[j], tb[j + 1]);
        visited += sheets[j]->splat(values, sx, sy, e, rect, [&](float r2, float dx, float dy) {
            const float tc = tx * dx + ty * dy;
            if (closed)
                return fp.lookup(r2) * closed->fraction(r2, ds * (t0 - tc), ds * (t1 - tc)) * scale;
            return table.section(r2, ds * (t0 - tc), ds * (t1 - tc)) * scale;
        });
    }
    return visited;
}

template <int NCh>
int splatSections(SheetBuffer<NCh>* const* sheets, int n, const float (&values)[NCh], float sx,
                  float sy, const footprint::EllipticalFootprint& e, const PixelRect& rect,
                  const footprint::SlabTable& table, const footprint::FootprintPoly* poly,
                  const float* tb, bool pairNarrowRows = true) {
#if defined(FOOTPRINT_HAVE_LANES)
    if constexpr (NCh != kLabelChannels)  // labels select by max: the scalar loop
        if (footprint::cpuHasLanes()) {
            const footprint::GaussianSlab* closed = table.closedForm();
            if (!closed)
                return splatSectionsLanes(sheets, n, values, sx, sy, e, rect, table, poly, tb);
            // Flat when the boundaries' depths vary over the footprint by < 1e-6 kernel units.
            const float drift =
                e.depthScale * (std::abs(e.tx) * e.halfWidth + std::abs(e.ty) * e.halfHeight);
            if (drift <= 1e-6f && n < kMaxFlat && pairNarrowRows && rect.x1 - rect.x0 < 4)
                return splatSectionsPairedLanes(sheets, n, values, sx, sy, e, rect,
                                                table.footprint(), *closed, poly, tb);
            if (drift <= 1e-6f && n < kMaxFlat)
                return splatSectionsClosedLanes<NCh, true>(sheets, n, values, sx, sy, e, rect,
                                                           table.footprint(), *closed, poly, tb);
            return splatSectionsClosedLanes<NCh, false>(sheets, n, values, sx, sy, e, rect,
                                                        table.footprint(), *closed, poly, tb);
        }
#endif
    return splatSectionsScalar(sheets, n, values, sx, sy, e, rect, table, poly, tb);
}

}  // namespace

int cutIntoSlabs(SheetBuffer<4>* const* sheets, int n, const float (&values)[4], float sx, float sy,
                 const footprint::EllipticalFootprint& e, const PixelRect& rect,
                 const footprint::SlabTable& table, const footprint::FootprintPoly* poly,
                 const float* tb, bool pairNarrowRows) {
    return splatSections(sheets, n, values, sx, sy, e, rect, table, poly, tb, pairNarrowRows);
}

namespace {

/// Each splat is cut into the slabs it crosses: `span` slabs from `key` in visiting order;
/// only those in [lo, hi) (exact bricks cut one group of slabs at a time: slab_sheets.h).
struct SlabSections {
    const TileInputs& in;
    const footprint::SlabTable& table;
    bool ftb;
    std::uint32_t lo = 0, hi = ~std::uint32_t(0);

    std::uint32_t key(const SheetRecord& s) const { return s.key; }
    std::uint32_t span(const SheetRecord& s) const { return s.span; }
    template <int NCh>
    int cut(SheetBuffer<NCh>* const* sheets, const SheetRecord& s, const float (&v)[NCh],
            const footprint::EllipticalFootprint& e, const PixelRect& r) const {
        // Slab boundaries in visiting order, as depths along this splat's rays relative to
        // its centre: t = (plane depth - centre) / cos. Boundary b is plane first + b front
        // to back, last + 1 - b back to front (key = slabs - 1 - last).
        const ProjectedSplats& proj = in.proj;
        const int n = int(s.span);
        float tb[kMaxSpan + 1];
        const float perRay = proj.perspective ? proj.depthPerRay[s.id] : 1.0f;
        const std::uint32_t base = ftb ? s.key : in.plan.sheets - s.key;
        for (int b = 0; b <= n; ++b) {
            const std::uint32_t plane = ftb ? base + std::uint32_t(b) : base - std::uint32_t(b);
            tb[b] = (in.plan.depthOrigin + float(plane) * in.plan.thickness - s.depth) * perRay;
        }
        const int j0 = lo > s.key ? int(lo - s.key) : 0;
        const int j1 = hi - s.key < s.span ? int(hi - s.key) : n;
        return splatSections(sheets + j0, j1 - j0, v, s.sx, s.sy, e, r, table,
                             in.scene.poly ? &*in.scene.poly : nullptr, tb + j0);
    }
};

/// The image-aligned splatter's state per scene (Scene::Impl::state), each part made on
/// first use: the slab-section table and the splats ordered (stably) by slice index along an
/// axis.
class SlabState {
  public:
    explicit SlabState(const Scene::Impl& scene) : scene_(scene) {}

    const footprint::SlabTable& slabTable() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!slabTable_) {
            const Quality& q = scene_.settings.quality;
            try {
                slabTable_ = std::make_unique<footprint::SlabTable>(
                    scene_.kernel, q.slabRadialResolution, q.slabDepthResolution);
            } catch (const std::invalid_argument& e) {
                throw Error(std::string("slab table: ") + e.what());
            }
        }
        return *slabTable_;
    }

    /// The splat indices in slice order along `axis`, or null for axis 2: the list is in
    /// (k, j, i) order already, so the order is the identity and is not stored.
    const std::vector<std::uint32_t>* sliceOrder(int axis) {
        if (axis == 2) return nullptr;
        std::lock_guard<std::mutex> lock(mutex_);
        std::unique_ptr<std::vector<std::uint32_t>>& o = sliceOrder_[axis];
        if (!o) {
            const SplatList& splats = scene_.splats;
            const std::vector<std::uint16_t>& index = axis == 0 ? splats.i : splats.j;
            // Counting sort on the 16-bit slice indices (no widened copy of the keys).
            std::vector<std::uint32_t> next(std::size_t(scene_.volume->dims[axis]) + 1, 0);
            for (std::uint16_t q : index) ++next[std::size_t(q) + 1];
            for (std::size_t q = 1; q < next.size(); ++q) next[q] += next[q - 1];
            o = std::make_unique<std::vector<std::uint32_t>>(index.size());
            for (std::size_t n = 0; n < index.size(); ++n)
                (*o)[next[index[n]]++] = std::uint32_t(n);
        }
        return o.get();
    }

  private:
    const Scene::Impl& scene_;
    std::mutex mutex_;
    std::unique_ptr<footprint::SlabTable> slabTable_;
    std::unique_ptr<std::vector<std::uint32_t>> sliceOrder_[2];
};

class ImageAligned final : public Splatter {
  public:
    SheetPlan order(const Scene::Impl& scene, const Camera& camera, const RenderSettings& s,
                    FrameWorkspace& work, RenderStats& stats) const override {
        const ProjectedSplats& proj = work.proj;
        const std::size_t count = proj.depth.size();
        const float ext = proj.depthExtent;
        // The slab grid covers every kernel's depth range [depth - ext, depth + ext].
        float zmin = 0.0f, zmax = 0.0f;
        if (count > 0) {
            zmin = zmax = proj.depth[0];
            for (float d : proj.depth) {
                zmin = std::min(zmin, d);
                zmax = std::max(zmax, d);
            }
        }
        zmin -= ext;
        zmax += ext;
        const float thickness = float(s.quality.slab * scene.volume->minSpacing());
        return orderOnSlabs(scene, camera, s, work, stats, zmin,
                            double(std::floor((zmax - zmin) / thickness)) + 1);
    }

    Image rasterize(const TileInputs& in, FrameWorkspace&, RenderStats* stats) const override {
        const SlabSections cutter{in, in.scene.state<SlabState>().slabTable(),
                                  in.settings.order == CompositeOrder::FrontToBack};
        return rasterizeWithPolicy(in, cutter, stats);
    }
};

}  // namespace

SheetPlan orderOnSlabs(const Scene::Impl& scene, const Camera& camera, const RenderSettings& s,
                       FrameWorkspace& work, RenderStats& stats, float zmin, double slabCount) {
    const ProjectedSplats& proj = work.proj;
    const std::size_t count = proj.depth.size();
    const bool ftb = s.order == CompositeOrder::FrontToBack;
    const float thickness = float(s.quality.slab * scene.volume->minSpacing());
    const float ext = proj.depthExtent;
    const double span = double(std::ceil(2.0f * ext / thickness)) + 2;
    if (!(slabCount <= kMaxSlabs) || !(span <= kMaxSpan))
        throw Error("image-aligned splatter: the volume's depth range (" +
                    std::to_string(slabCount * thickness) + ") at slab thickness " +
                    std::to_string(thickness) +
                    " would need too many slabs; use a thicker --slab or check the spacing");
    const std::uint32_t slabs = std::uint32_t(slabCount);
    work.key.resize(count);
    work.span.resize(count);
    for (std::size_t n = 0; n < count; ++n) {
        // (Exact bricks: a brick's ghost kernels may lie before the grid; never visited.)
        const std::uint32_t first = std::min(
            slabs - 1, std::uint32_t(std::max(0.0f, (proj.depth[n] - ext - zmin) / thickness)));
        const std::uint32_t last = std::min(
            slabs - 1, std::uint32_t(std::max(0.0f, (proj.depth[n] + ext - zmin) / thickness)));
        work.key[n] = ftb ? first : slabs - 1 - last;
        work.span[n] = last - first + 1;
    }
    // Within a slab, splats are visited in slice order along the major axis, which keeps
    // the accesses to the splat arrays coherent.
    const int m = sheetAxis(camera.view, scene.volume->spacing).axis;
    orderByKey(work.key, slabs, scene.state<SlabState>().sliceOrder(m), work.order);
    SheetPlan plan;
    plan.sheets = slabs;
    plan.ring = std::uint32_t(span);
    plan.pathLength = thickness;
    plan.normal = camera.view;
    plan.depthOrigin = zmin;
    plan.thickness = thickness;
    stats.slabs = slabs;
    return plan;
}

void addSlabSheets(const TileInputs& in, std::uint32_t first, std::uint32_t count, float* blocks,
                   int* rects) {
    withPolicy(in.policy, [&](const auto& policy) {
        using Policy = std::decay_t<decltype(policy)>;
        constexpr int NCh = Policy::kChannels;
        const SlabSections cutter{in, in.scene.state<SlabState>().slabTable(),
                                  in.settings.order == CompositeOrder::FrontToBack, first,
                                  first + count};
        const TileGrid& g = in.bins.grid;
        const std::size_t block = std::size_t(NCh) * g.tileSize * g.tileSize;
        struct Group {
            std::vector<std::unique_ptr<SheetBuffer<NCh>>> sheets;
        };
        tbb::enumerable_thread_specific<Group> groups;
        tbb::parallel_for(0, g.count(), 1, [&](int t) {
            const BinnedSplats src{in, t};
            if (src.begin() == src.end()) return;
            const DenormalsAreZero ftz;
            const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
            const int w = std::min(g.tileSize, g.width - ox),
                      h = std::min(g.tileSize, g.height - oy);
            Group& group = groups.local();
            while (group.sheets.size() < count)
                group.sheets.push_back(
                    std::make_unique<SheetBuffer<NCh>>(ox, oy, g.tileSize, g.tileSize));
            for (std::uint32_t k = 0; k < count; ++k) group.sheets[k]->moveTo(ox, oy, w, h);
            // The records are in key order: skip those that end before the group.
            const SheetRecord* const records = &in.bins.records[0];
            std::uint32_t q =
                std::uint32_t(std::partition_point(records + src.begin(), records + src.end(),
                                                   [&](const SheetRecord& r) {
                                                       return r.key + in.plan.ring <= first;
                                                   }) -
                              records);
            SheetBuffer<NCh>* target[kMaxRing];
            for (; q < src.end() && src.record(q).key < first + count; ++q) {
                const SheetRecord& rec = src.record(q);
                if (rec.key + rec.span <= first) continue;
                const PixelRect r = clipToTile(src.rect(rec), g, ox, oy);
                const std::uint32_t j0 = first > rec.key ? first - rec.key : 0;
                const std::uint32_t j1 = std::min(rec.span, first + count - rec.key);
                for (std::uint32_t j = j0; j < j1; ++j)
                    target[j] = group.sheets[rec.key + j - first].get();
                float v[NCh];
                splatValues<Policy>(in, rec.id, v);
                cutter.cut(target, rec, v, src.ellipse(rec), r);
            }
            // Add the dirty sheets into the tile's blocks and widen their rectangles.
            for (std::uint32_t k = 0; k < count; ++k) {
                SheetBuffer<NCh>& sheet = *group.sheets[k];
                if (!sheet.dirty()) continue;
                int x0, y0, x1, y1;
                sheet.dirtyBounds(x0, y0, x1, y1);
                x1 = std::min(x1, w - 1);
                const std::size_t at = std::size_t(t) * count + k;
                float* out = blocks + at * block;
                for (int c = 0; c < NCh; ++c)
                    for (int y = y0; y <= y1; ++y) {
                        const float* row = sheet.row(c, y);
                        float* o = out + std::size_t(c) * g.tileSize * g.tileSize +
                                   std::size_t(y) * g.tileSize;
                        for (int x = x0; x <= x1; ++x) o[x] += row[x];
                    }
                int* rect = rects + 4 * at;
                rect[0] = std::min(rect[0], x0);
                rect[1] = std::min(rect[1], y0);
                rect[2] = std::min(rect[2], -x1);
                rect[3] = std::min(rect[3], -y1);
                sheet.discard();
            }
        });
    });
}

const Splatter& imageAlignedSplatter() {
    static const ImageAligned splatter;
    return splatter;
}

}  // namespace splat
