// The axis-aligned sheet-buffer splatter (L. Westover, "Footprint evaluation for volume
// rendering", SIGGRAPH 1990): sheets are the volume slices perpendicular to the volume
// axis most parallel to the ray in index space (the major axis of S^-1 view); every kernel
// is integrated whole (its footprint fp(r^2), footprint/footprint_table.h) into the sheet of
// its slice, and the sheets are composited in visibility order. When the major axis
// changes (at 45 degrees for isotropic voxels) the sheets change orientation: that is the
// popping artifact the image-aligned splatter removes.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>

#include "footprint/lanes.h"
#include "splatters/cell_index.h"
#include "splatters/footprint_lanes.h"
#include "splatters/splatter.h"

namespace splat {

SheetAxis sheetAxis(const glm::dvec3& view, const glm::dvec3& spacing) {
    const glm::dvec3 d = view / spacing;  // S^-1 view
    const glm::dvec3 a = glm::abs(d);
    const int m = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    return {m, d[m] >= 0 ? 1 : -1};
}

namespace {

#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
/// Per-frame footprint stamps (orthographic views, one ellipse for every splat): the
/// footprint rasterised once per frame at `phases` x `phases` sub-pixel phases, so that a
/// splat adds a stamp, the one of its phase rounded to the nearest 1 / phases pixel (its
/// position moved by at most 1 / (2 phases) pixels along each axis), with no polynomial per
/// pixel.
class PhaseStamps {
  public:
    PhaseStamps(const footprint::EllipticalFootprint& e, const footprint::FootprintTable& table,
                int phases)
        : phases_(phases),
          k0_(int(std::floor(-e.halfWidth)) - 1),
          l0_(int(std::floor(-e.halfHeight)) - 1),
          width_(int(std::ceil(e.halfWidth)) + 2 - k0_),
          height_(int(std::ceil(e.halfHeight)) + 2 - l0_),
          stride_((width_ + 7) / 8 * 8 + 8) {
        w_.assign(std::size_t(phases + 1) * (phases + 1) * height_ * stride_, 0.0f);
        for (int py = 0; py <= phases; ++py)
            for (int px = 0; px <= phases; ++px)
                for (int l = 0; l < height_; ++l)
                    for (int k = 0; k < width_; ++k) {
                        const float dx = float(k0_ + k) - float(px) / float(phases),
                                    dy = float(l0_ + l) - float(py) / float(phases);
                        const float r2 = e.r2(dx, dy);
                        if (r2 < table.r2Max())
                            w_[index(px, py, l) + std::size_t(k)] = table.lookup(r2) * e.scale;
                    }
    }
    /// Adds values * stamp for a splat at (sx, sy) to the pixels of `rect`.
    template <int NCh>
    int add(SheetBuffer<NCh>& sheet, const float (&values)[NCh], float sx, float sy,
            const PixelRect& rect) const {
        // Pixel x's centre x + 0.5 lies k - phase from the splat, k = x - base.
        const float fx = sx - 0.5f, fy = sy - 0.5f;
        const int bx = int(std::floor(fx)), by = int(std::floor(fy));
        const int px = int(std::lround((fx - float(bx)) * float(phases_)));
        const int py = int(std::lround((fy - float(by)) * float(phases_)));
        const int ox = sheet.originX(), oy = sheet.originY();
        const int x0 = rect.x0 - ox, x1 = rect.x1 - ox, y0 = rect.y0 - oy, y1 = rect.y1 - oy;
        sheet.markDirty(x0, x1, y0, y1);
        const std::ptrdiff_t plane = NCh > 1 ? sheet.row(1, 0) - sheet.row(0, 0) : 0;
        __m256 vv[NCh];
        for (int c = 0; c < NCh; ++c) vv[c] = _mm256_set1_ps(values[c]);
        const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        const int k = rect.x0 - bx - k0_, n = x1 - x0 + 1;
        for (int y = y0; y <= y1; ++y) {
            const float* w = &w_[index(px, py, y + oy - by - l0_)] + k;
            float* const base = sheet.row(0, y) + x0;
            for (int i = 0; i < n; i += 8) {
                const __m256i mask = _mm256_cmpgt_epi32(_mm256_set1_epi32(n - i), lane);
                const __m256 wv = _mm256_maskload_ps(w + i, mask);
                float* p = base + i;
                for (int c = 0; c < NCh; ++c, p += plane)
                    _mm256_storeu_ps(p, _mm256_fmadd_ps(vv[c], wv, _mm256_loadu_ps(p)));
            }
        }
        return n * (y1 - y0 + 1);
    }

  private:
    std::size_t index(int px, int py, int l) const {
        return ((std::size_t(py) * (phases_ + 1) + std::size_t(px)) * height_ + std::size_t(l)) *
               stride_;
    }
    int phases_, k0_, l0_, width_, height_, stride_;
    std::vector<float> w_;
};
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
            return splatFootprintVector(sheet, values, sx, sy, e, rect, table, poly);
#endif
    return splatFootprintScalar(sheet, values, sx, sy, e, rect, table, poly);
}

/// The splats and runs one part of a slab lists (AxisAligned's gather).
struct GatherPart {
    std::vector<std::uint32_t> ids, runs;
};

/// Each splat lies in the one sheet of its slice along the major axis.
struct WholeFootprints {
    const std::vector<std::uint16_t>& index;  ///< slice index of each splat along the axis
    bool ascending;
    std::uint32_t slices;
    const footprint::FootprintTable& table;
    const footprint::FootprintPoly* poly;
#if defined(FOOTPRINT_HAVE_LANES)
    const PhaseStamps* stamps = nullptr;    ///< per-frame footprint stamps, when asked for
    const Degree5Lanes* degree5 = nullptr;  ///< the frame's polynomial lanes, where they fit
#endif

    template <class Record>  // SplatRecord or RunRecord
    std::uint32_t key(const Record& s) const {
        return ascending ? s.slice : slices - 1 - s.slice;  // s.slice = index[s.id]
    }
    /// What binning copies into each record's `slice`.
    const std::uint16_t* sliceIndex() const { return index.data(); }
    std::uint32_t span(const SplatRecord&) const { return 1; }
    template <int NCh>
    int cut(SheetBuffer<NCh>* const* sheets, const SplatRecord& s, const float (&v)[NCh],
            const footprint::EllipticalFootprint& e, const PixelRect& r) const {
#if defined(FOOTPRINT_HAVE_LANES)
        if constexpr (NCh != kLabelChannels) {
            if (stamps) return stamps->add(*sheets[0], v, s.sx, s.sy, r);
            if (degree5)
                return splatFootprintLanes(*sheets[0], v, s.sx, s.sy, e, r, table, *degree5);
        }
#endif
        return splatFootprint(*sheets[0], v, s.sx, s.sy, e, r, table, poly);
    }
};

/// The axis-aligned splatter's chunks (SheetChunks::gather): chunk c is the slab of
/// kCellWidth slices c-th in visiting order, read from the scene's cells (CellIndex) in runs
/// of consecutive splats (no sorted copy of the list), leaving out the bricks found hidden.
/// Binning sorts each tile's records by slice.
class SlabGather {
  public:
    static constexpr int kWidth = CellIndex::kCellWidth;

    SlabGather(const Scene::Impl& scene, CellIndex& index, int axis, std::size_t slabs,
               bool ascending)
        : scene_(scene),
          cells_(index.cellStarts()),
          brickCounts_(index.brickCounts()),
          bricks_(index.bricks()),
          cellsX_(std::size_t(index.cellsX())),
          m_(axis),
          u_(axis == 0 ? 1 : 0),
          v_(axis == 2 ? 1 : 2),
          slabs_(slabs),
          ascending_(ascending) {}

    /// Lists chunk c's splats into `ids`, cut into `runs`; returns the splats left out.
    std::size_t operator()(std::size_t c, std::vector<std::uint32_t>& ids,
                           std::vector<std::uint32_t>& runs, const BrickTest& visible) {
        const std::size_t slab = ascending_ ? c : slabs_ - 1 - c;
        const std::size_t hidden = markBricks(slab, visible);
        listCells(slab);
        joinParts(ids, runs);
        return hidden;
    }

  private:
    /// The slab's slices along the axis: [first, end).
    std::size_t firstSlice(std::size_t slab) const { return slab * kWidth; }
    std::size_t endSlice(std::size_t slab) const {
        return std::min<std::size_t>(firstSlice(slab) + kWidth, scene_.volume->dims[m_]);
    }
    std::size_t bricksU() const { return std::size_t(bricks_[u_]); }
    std::size_t bricksV() const { return std::size_t(bricks_[v_]); }
    /// Whether the brick holding voxel (iu, iv) of the slab (u, v: the other two axes) is
    /// read.
    bool shown(std::size_t iu, std::size_t iv) const {
        return state_[iv / kWidth * bricksU() + iu / kWidth] != 0;
    }

    /// The slab is one layer of bricks of kWidth^3 voxels. Each is tested as one against the
    /// tiles' opacity: the cells of an empty or hidden brick are not read at all
    /// (state_[bu + bv * bricksU] = 0), the splats of a hidden one counted from brickCounts.
    /// Cells of the others are read in the same order as without bricks, so the image is the
    /// same. Returns the splats of the hidden bricks.
    std::size_t markBricks(std::size_t slab, const BrickTest& visible) {
        const int m = m_, u = u_, v = v_;
        const glm::ivec3 d = scene_.volume->dims, nb = bricks_;
        const std::size_t q0 = firstSlice(slab), q1 = endSlice(slab);
        const std::size_t nu = bricksU(), nv = bricksV();
        state_.assign(nu * nv, 0);
        std::vector<std::size_t> left(nv, 0);
        tbb::parallel_for(std::size_t(0), nv, [&](std::size_t bv) {
            for (std::size_t bu = 0; bu < nu; ++bu) {
                glm::ivec3 bi;
                bi[m] = int(slab);
                bi[u] = int(bu);
                bi[v] = int(bv);
                const std::uint32_t n =
                    brickCounts_[(std::size_t(bi.z) * nb.y + std::size_t(bi.y)) * nb.x + bi.x];
                if (n == 0) continue;
                glm::ivec3 lo = bi * kWidth, hi = glm::min(d, lo + kWidth) - 1;
                lo[m] = int(q0);
                hi[m] = int(q1) - 1;
                if (visible(lo, hi))
                    state_[bv * nu + bu] = 1;
                else
                    left[bv] += n;
            }
        });
        std::size_t hidden = 0;
        for (std::size_t h : left) hidden += h;
        return hidden;
    }

    /// The cells of the shown bricks, listed in parts (in parallel; joined in order by
    /// joinParts): part p holds slice q0 + p / bricksV (m = 0: all of them) and the v-brick
    /// p % bricksV. One run per non-empty cell (m = 0: per slice of kWidth cells): its splats
    /// lie on one line of voxels between its first and last, in one sheet.
    void listCells(std::size_t slab) {
        const int m = m_;
        const glm::ivec3 d = scene_.volume->dims;
        const std::size_t q0 = firstSlice(slab), q1 = endSlice(slab);
        const std::size_t ny = std::size_t(d.y), cx = cellsX_, nv = bricksV();
        const std::vector<std::uint32_t>& cells = cells_;
        nParts_ = m == 0 ? nv : (q1 - q0) * nv;
        if (parts_.size() < nParts_) parts_.resize(nParts_);
        tbb::parallel_for(std::size_t(0), nParts_, [&](std::size_t p) {
            GatherPart& part = parts_[p];
            part.ids.clear();
            part.runs.clear();
            auto add = [&](std::size_t cell) {
                if (cells[cell] == cells[cell + 1]) return;
                for (std::size_t q = cells[cell]; q < cells[cell + 1]; ++q)
                    part.ids.push_back(std::uint32_t(q));
                part.runs.push_back(std::uint32_t(part.ids.size()));
            };
            const std::size_t bv = p % nv, slice = q0 + p / nv;
            const std::size_t v0 = bv * kWidth, v1 = std::min<std::size_t>(v0 + kWidth, d[v_]);
            if (m == 2) {  // u = i (one cell per brick), v = j
                for (std::size_t j = v0; j < v1; ++j)
                    for (std::size_t ci = 0; ci < cx; ++ci)
                        if (shown(ci * kWidth, j)) add((slice * ny + j) * cx + ci);
            } else if (m == 1) {  // u = i, v = k: slice-major, already in sheet order
                for (std::size_t k = v0; k < v1; ++k)
                    for (std::size_t ci = 0; ci < cx; ++ci)
                        if (shown(ci * kWidth, k)) add((k * ny + slice) * cx + ci);
            } else {  // u = j, v = k; the slab is cell column `slab`
                listColumnCells(slab, v0, v1, part);
            }
        });
    }

    /// Axis 0: a cell's splats lie in different slices, so the cells of kWidth rows j are
    /// listed slice by slice instead, each slice's splats one run along j (per slice the
    /// same order as row by row: k, then j), for the v-bricks' rows k in [v0, v1).
    void listColumnCells(std::size_t slab, std::size_t v0, std::size_t v1, GatherPart& part) const {
        const std::size_t q0 = firstSlice(slab), q1 = endSlice(slab);
        const std::size_t ny = std::size_t(scene_.volume->dims.y), cx = cellsX_;
        const std::vector<std::uint32_t>& cells = cells_;
        const std::vector<std::uint16_t>& si = scene_.splats.i;
        std::uint32_t at[kWidth], stop[kWidth];
        for (std::size_t k = v0; k < v1; ++k)
            for (std::size_t j0 = 0; j0 < ny; j0 += kWidth) {
                if (!shown(j0, k)) continue;
                const std::size_t rows = std::min<std::size_t>(kWidth, ny - j0);
                for (std::size_t r = 0; r < rows; ++r) {
                    const std::size_t cell = (k * ny + j0 + r) * cx + slab;
                    at[r] = cells[cell];
                    stop[r] = cells[cell + 1];
                }
                for (std::size_t i = q0; i < q1; ++i) {
                    const std::size_t before = part.ids.size();
                    for (std::size_t r = 0; r < rows; ++r)
                        while (at[r] < stop[r] && si[at[r]] == i) part.ids.push_back(at[r]++);
                    if (part.ids.size() != before)
                        part.runs.push_back(std::uint32_t(part.ids.size()));
                }
            }
    }

    /// The parts' splats and runs, joined in order.
    void joinParts(std::vector<std::uint32_t>& ids, std::vector<std::uint32_t>& runs) const {
        std::size_t total = 0, runCount = 0;
        for (std::size_t p = 0; p < nParts_; ++p) {
            total += parts_[p].ids.size();
            runCount += parts_[p].runs.size();
        }
        ids.resize(total);
        runs.resize(runCount + 1);
        runs[0] = 0;
        std::size_t at = 0, r = 1;
        for (std::size_t p = 0; p < nParts_; ++p) {
            std::copy(parts_[p].ids.begin(), parts_[p].ids.end(), ids.begin() + std::ptrdiff_t(at));
            for (std::uint32_t e : parts_[p].runs) runs[r++] = std::uint32_t(at + e);
            at += parts_[p].ids.size();
        }
    }

    const Scene::Impl& scene_;
    const std::vector<std::uint32_t>& cells_;
    const std::vector<std::uint32_t>& brickCounts_;
    glm::ivec3 bricks_;
    std::size_t cellsX_;
    int m_, u_, v_;
    std::size_t slabs_;
    bool ascending_;
    std::vector<std::uint8_t> state_;  ///< per brick of the slab: read (1) or not
    std::vector<GatherPart> parts_;
    std::size_t nParts_ = 0;
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
        // direction.
        const std::size_t slabs = (plan.sheets + SlabGather::kWidth - 1) / SlabGather::kWidth;
        work.chunks.count = slabs;
        work.chunks.gather = SlabGather(scene, scene.state<CellIndex>(), m, slabs, plan.ascending);
        stats.sheetAxis = m;
        stats.sheetSign = sa.sign;
        return plan;
    }

    bool streams() const override { return true; }

    Image rasterize(const TileInputs& in, FrameWorkspace& work, RenderStats* stats) const override {
        const SplatList& s = in.scene.splats;
        const int m = in.plan.axis;
        WholeFootprints cutter{m == 0 ? s.i : (m == 1 ? s.j : s.k), in.plan.ascending,
                               in.plan.sheets, in.scene.table,
                               in.scene.poly ? &*in.scene.poly : nullptr};
#if defined(FOOTPRINT_HAVE_LANES)
        // Quality::factorisedSheets < 0 (an experiment beside factorised sheets): per-frame
        // footprint stamps at -factorisedSheets phases per pixel, orthographic views only.
        std::optional<PhaseStamps> stamps;
        // The polynomial's coefficients loaded once per frame instead of once per splat.
        std::optional<Degree5Lanes> degree5;
        if (cutter.poly && Degree5Lanes::fits(*cutter.poly) && footprint::cpuHasLanes()) {
            degree5.emplace(*cutter.poly);
            cutter.degree5 = &*degree5;
        }
        const int phases = -in.settings.quality.factorisedSheets;
        if (phases > 0 && !in.camera.perspective() && footprint::cpuHasLanes()) {
            const SplatProjector projector(
                s, in.camera, in.scene.volume->spacing, in.scene.kernel.radius(),
                footprintFilter(in.scene.kernel, in.settings.quality, in.settings.mode, in.camera,
                                *in.scene.volume, in.scene.level));
            stamps.emplace(projector.shared(), in.scene.table, phases);
            cutter.stamps = &*stamps;
        }
#endif
        return rasterizeChunksWithPolicy(in, cutter, work.chunks, work.chunkBins, stats);
    }
};

}  // namespace

const Splatter& axisAlignedSplatter() {
    static const AxisAligned splatter;
    return splatter;
}

}  // namespace splat
