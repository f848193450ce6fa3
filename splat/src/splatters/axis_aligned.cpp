// The axis-aligned sheet-buffer splatter (L. Westover, "Footprint evaluation for volume
// rendering", SIGGRAPH 1990): sheets are the volume slices perpendicular to the volume
// axis most parallel to the ray in index space (the major axis of S^-1 view); every kernel
// is integrated whole (its footprint fp(r^2), footprint/footprint_table.h) into the sheet of
// its slice, and the sheets are composited in visibility order. When the major axis
// changes (at 45 degrees for isotropic voxels) the sheets change orientation: that is the
// popping artifact the image-aligned splatter removes.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "footprint/lanes.h"
#include "splatters/splatter.h"

namespace splat {

SheetAxis sheetAxis(const glm::dvec3& view, const glm::dvec3& spacing) {
    const glm::dvec3 d = view / spacing;  // S^-1 view
    const glm::dvec3 a = glm::abs(d);
    const int m = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    return {m, d[m] >= 0 ? 1 : -1};
}

namespace {

/// Adds values * fp(r^2) * e.scale, the whole footprint, to the pixels of `rect`: eight
/// pixels at a time where AVX2 is available (fp from the polynomial when given).
#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
template <int NCh>
int splatFootprintLanes(SheetBuffer<NCh>& sheet, const float (&values)[NCh], float sx, float sy,
                        const footprint::EllipticalFootprint& e, const PixelRect& rect,
                        const footprint::FootprintTable& table,
                        const footprint::FootprintPoly* poly) {
    const int ox = sheet.originX(), oy = sheet.originY();
    const int x0 = rect.x0 - ox, x1 = rect.x1 - ox, y0 = rect.y0 - oy, y1 = rect.y1 - oy;
    sheet.markDirty(x0, x1, y0, y1);
    const __m256 lane = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256 va = _mm256_set1_ps(e.a), vScale = _mm256_set1_ps(e.scale);
    const __m256 vMax = _mm256_set1_ps(table.r2Max()), zero = _mm256_setzero_ps();
    const footprint::FootprintLanes footprintOf(table, poly);
    __m256 vv[NCh];
    for (int c = 0; c < NCh; ++c) vv[c] = _mm256_set1_ps(values[c]);
    for (int y = y0; y <= y1; ++y) {
        const float dy = float(y + oy) + 0.5f - sy;
        // r^2 = a (dx + beta dy)^2 + gamma dy^2 (EllipticalFootprint::r2).
        const float gyy = e.gamma * dy * dy, shift = e.beta * dy;
        const __m256 vgyy = _mm256_set1_ps(gyy), vshift = _mm256_set1_ps(shift);
        const __m256 lastX = _mm256_set1_ps(float(x1) + 0.5f);
        const __m256 firstX = _mm256_set1_ps(float(x0) - 0.5f);
        for (int x = x0 & ~7; x <= x1; x += 8) {
            const __m256 px = _mm256_add_ps(_mm256_set1_ps(float(x)), lane);
            const __m256 q =
                _mm256_add_ps(_mm256_add_ps(px, _mm256_set1_ps(float(ox) + 0.5f - sx)), vshift);
            const __m256 r2 = _mm256_fmadd_ps(_mm256_mul_ps(va, q), q, vgyy);
            const __m256 inside =
                _mm256_and_ps(_mm256_cmp_ps(r2, vMax, _CMP_LT_OQ),
                              _mm256_and_ps(_mm256_cmp_ps(px, lastX, _CMP_LT_OQ),
                                            _mm256_cmp_ps(px, firstX, _CMP_GT_OQ)));
            const __m256 fp = footprintOf(_mm256_max_ps(r2, zero));
            const __m256 w = _mm256_and_ps(inside, _mm256_mul_ps(fp, vScale));
            for (int c = 0; c < NCh; ++c) {
                float* p = sheet.row(c, y) + x;
                _mm256_storeu_ps(p, _mm256_fmadd_ps(vv[c], w, _mm256_loadu_ps(p)));
            }
        }
    }
    return (x1 - x0 + 1) * (y1 - y0 + 1);
}
FOOTPRINT_LANES_END
#endif

template <int NCh>
int splatFootprintScalar(SheetBuffer<NCh>& sheet, const float (&values)[NCh], float sx, float sy,
                         const footprint::EllipticalFootprint& e, const PixelRect& rect,
                         const footprint::FootprintTable& table, const footprint::FootprintPoly*) {
    // Without AVX2 the table's own lookup is as fast as the polynomial and exact.
    const float scale = e.scale;
    return sheet.splat(values, sx, sy, e, rect,
                       [&](float r2, float, float) { return table.lookup(r2) * scale; });
}

template <int NCh>
int splatFootprint(SheetBuffer<NCh>& sheet, const float (&values)[NCh], float sx, float sy,
                   const footprint::EllipticalFootprint& e, const PixelRect& rect,
                   const footprint::FootprintTable& table, const footprint::FootprintPoly* poly) {
#if defined(FOOTPRINT_HAVE_LANES)
    if constexpr (NCh != kLabelChannels)  // labels select by max: the scalar loop
        if (footprint::cpuHasLanes())
            return splatFootprintLanes(sheet, values, sx, sy, e, rect, table, poly);
#endif
    return splatFootprintScalar(sheet, values, sx, sy, e, rect, table, poly);
}

/// Each splat lies in the one sheet of its slice along the major axis.
struct WholeFootprints {
    const std::vector<std::uint16_t>& index;  ///< slice index of each splat along the axis
    bool ascending;
    std::uint32_t slices;
    const footprint::FootprintTable& table;
    const footprint::FootprintPoly* poly;

    std::uint32_t key(std::uint32_t id) const {
        return ascending ? index[id] : slices - 1 - index[id];
    }
    std::uint32_t span(std::uint32_t) const { return 1; }
    template <int NCh>
    int cut(SheetBuffer<NCh>* const* sheets, std::uint32_t, const float (&v)[NCh], float sx,
            float sy, const footprint::EllipticalFootprint& e, const PixelRect& r) const {
        return splatFootprint(*sheets[0], v, sx, sy, e, r, table, poly);
    }
};

class AxisAligned final : public Splatter {
  public:
    SheetPlan order(const Scene::Impl& scene, const Camera& camera, const RenderSettings& s,
                    FrameWorkspace& work, RenderStats& stats) const override {
        const Volume& volume = *scene.volume;
        const SheetAxis sa = sheetAxis(camera.view, volume.spacing);
        const int m = sa.axis;
        SheetPlan plan;
        plan.axis = m;
        plan.sign = sa.sign;
        plan.ascending = (sa.sign > 0) == (s.order == CompositeOrder::FrontToBack);
        plan.sheets = std::uint32_t(volume.dims[m]);
        plan.ring = 1;
        // A ray crosses the slab around one slice over spacing_m / |view_m| world units.
        plan.pathLength = float(volume.spacing[m] / std::abs(camera.view[m]));
        plan.normal = glm::dvec3(0.0);
        plan.normal[m] = 1.0;
        // Visiting order: slabs of kCellWidth slices in visibility order for the compositing
        // direction, each read from the scene's cells in runs of consecutive splats (no sorted
        // copy of the list); binning sorts each tile's records by slice.
        const Scene::Impl& sc = scene;
        const std::vector<std::uint32_t>& cells = scene.cellStarts();
        constexpr int kWidth = Scene::Impl::kCellWidth;
        const std::size_t slabs = (plan.sheets + kWidth - 1) / kWidth;
        const bool ascending = plan.ascending;
        work.chunks.count = slabs;
        work.chunks.gather = [&sc, &cells, m, slabs, ascending,
                              hidden = std::vector<std::uint8_t>()](
                                 std::size_t c, std::vector<std::uint32_t>& ids,
                                 std::vector<std::uint32_t>& runs,
                                 const BrickTest& visible) mutable {
            const glm::ivec3 d = sc.volume->dims;
            const std::size_t slab = ascending ? c : slabs - 1 - c, cx = std::size_t(sc.cellsX());
            const std::size_t q0 = slab * kWidth, q1 = std::min<std::size_t>(q0 + kWidth, d[m]);
            ids.clear();
            runs.assign(1, 0);
            // Bricks of kWidth^3 voxels: the slab's kWidth slices times kWidth x kWidth voxels
            // of the other two axes (u, v), tested as one against the tiles' opacity; the
            // cells of a hidden brick are left out (hidden[bu + bv * bricksU]). Cells are
            // still read in the same order, so the image is the same with or without this.
            const int u = m == 0 ? 1 : 0, v = m == 2 ? 1 : 2;
            const int bricksU = (d[u] + kWidth - 1) / kWidth,
                      bricksV = (d[v] + kWidth - 1) / kWidth;
            hidden.assign(std::size_t(bricksU) * bricksV, 0);
            if (visible.active())
                for (int bv = 0; bv < bricksV; ++bv)
                    for (int bu = 0; bu < bricksU; ++bu) {
                        glm::ivec3 lo, hi;
                        lo[m] = int(q0);
                        hi[m] = int(q1) - 1;
                        lo[u] = bu * kWidth;
                        hi[u] = std::min(d[u], lo[u] + kWidth) - 1;
                        lo[v] = bv * kWidth;
                        hi[v] = std::min(d[v], lo[v] + kWidth) - 1;
                        hidden[std::size_t(bv) * bricksU + bu] = !visible(lo, hi);
                    }
            auto brickHidden = [&](std::size_t iu, std::size_t iv) {
                return hidden[iv / kWidth * std::size_t(bricksU) + iu / kWidth] != 0;
            };
            // One run per non-empty cell: its splats lie on one row between its first and last.
            std::size_t left = 0;
            auto skip = [&](std::size_t cell) { left += cells[cell + 1] - cells[cell]; };
            auto add = [&](std::size_t cell) {
                if (cells[cell] == cells[cell + 1]) return;
                for (std::size_t q = cells[cell]; q < cells[cell + 1]; ++q)
                    ids.push_back(std::uint32_t(q));
                runs.push_back(std::uint32_t(ids.size()));
            };
            const std::size_t ny = std::size_t(d.y), nz = std::size_t(d.z);
            if (m == 2) {  // u = i (cells), v = j
                for (std::size_t k = q0; k < q1; ++k)
                    for (std::size_t j = 0; j < ny; ++j)
                        for (std::size_t ci = 0; ci < cx; ++ci)
                            brickHidden(ci * kWidth, j) ? skip((k * ny + j) * cx + ci)
                                                        : add((k * ny + j) * cx + ci);
            } else if (m == 1) {  // u = i (cells), v = k; slice-major: already in sheet order
                for (std::size_t j = q0; j < q1; ++j)
                    for (std::size_t k = 0; k < nz; ++k)
                        for (std::size_t ci = 0; ci < cx; ++ci)
                            brickHidden(ci * kWidth, k) ? skip((k * ny + j) * cx + ci)
                                                        : add((k * ny + j) * cx + ci);
            } else {  // u = j, v = k; the slab is cell column `slab`
                for (std::size_t k = 0; k < nz; ++k)
                    for (std::size_t j = 0; j < ny; ++j)
                        brickHidden(j, k) ? skip((k * ny + j) * cx + slab)
                                          : add((k * ny + j) * cx + slab);
            }
            return left;
        };
        stats.sheetAxis = m;
        stats.sheetSign = sa.sign;
        return plan;
    }

    bool streams() const override { return true; }

    Image rasterize(const TileInputs& in, FrameWorkspace& work, RenderStats* stats) const override {
        const SplatList& s = in.scene.splats;
        const int m = in.plan.axis;
        const WholeFootprints cutter{m == 0 ? s.i : (m == 1 ? s.j : s.k), in.plan.ascending,
                                     in.plan.sheets, in.scene.table,
                                     in.scene.poly ? &*in.scene.poly : nullptr};
        return rasterizeChunksWithPolicy(in, cutter, work.chunks, work.chunkBins, stats);
    }
};

}  // namespace

const Splatter& axisAlignedSplatter() {
    static const AxisAligned splatter;
    return splatter;
}

}  // namespace splat
