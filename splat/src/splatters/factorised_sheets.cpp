// Factorised sheets (see factorised_sheets.h): stamps, bands of the intermediate image,
// the warp.
#include "splatters/factorised_sheets.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>

#include "footprint/ellipse.h"
#include "footprint/lanes.h"
#include "frame/compositing.h"
#include "frame/stopwatch.h"
#include "splatters/cell_index.h"
#include "splatters/splatter.h"

namespace splat {

namespace detail {
/// Whether bands pass over hidden sheet rows by their spans (SheetRowSpans) and composite the
/// blocks a sheet wrote only (compositeSheet); off only in the test that checks the image is
/// the same without.
std::atomic<bool> factorisedSheetsSkipHidden{true};
}  // namespace detail

namespace {

constexpr int kBand = 16;  ///< intermediate rows per band: the unit of parallel work
constexpr int kBlock = 8;  ///< early termination: a band's opacity is tested per 8 columns
/// Samples per voxel when Quality::warpTolerance asks for factorised sheets and
/// Quality::factorisedSheets does not choose: two keep the per-splat frame's error on ch2
/// (docs/performance.md), and the edge tiles take the sharper edges.
constexpr int kEdgeTileSamples = 2;

/// The view's factorisation: sheets along axis m (sheet q, voxel (u, v) on the screen at
/// c + J (u + shear.x q, v + shear.y q)) and the intermediate grid, sample (a, b) at sheet
/// coordinates (U0 + a / n, V0 + b / n), of which the window [a0, a0 + width) x [b0, b0 +
/// height) covers the screen.
struct Factorisation {
    int m, u, v;
    int rowLength;   ///< voxels along u
    bool ascending;  ///< sheets visited in increasing q
    glm::dvec2 c, colU, colV, shear;
    double invDet;
    int n;
    double U0, V0;
    int a0, b0, width, height;
    footprint::EllipticalFootprint e;
    float r2Max;
    /// Stamp: columns [dA, dA + stampW) and rows [dB, dB + stampH) around a voxel's sample.
    int dA, dB, stampW, stampH;

    glm::dvec2 screen(double U, double V) const { return c + colU * U + colV * V; }
    /// Sheet coordinates (U, V) of a screen point.
    glm::dvec2 sheet(glm::dvec2 p) const {
        p -= c;
        return {(colV.y * p.x - colV.x * p.y) * invDet, (colU.x * p.y - colU.y * p.x) * invDet};
    }
};

Factorisation factorise(const Scene::Impl& scene, const Camera& camera, const RenderSettings& s) {
    const Volume& volume = *scene.volume;
    const SheetAxis sa = sheetAxis(camera.view, volume.spacing);
    Factorisation f;
    f.m = sa.axis;
    f.u = f.m == 0 ? 1 : 0;
    f.v = f.m == 2 ? 1 : 2;
    f.rowLength = volume.dims[f.u];
    f.ascending = (sa.sign > 0) == (s.order == CompositeOrder::FrontToBack);
    // The screen map of SplatProjector: x = cx + (w - eye) . right / pixel, y = cy - ... up.
    const glm::dvec3 rx = camera.right / camera.pixelSize, ry = camera.up / camera.pixelSize;
    const glm::dvec3 sp = scene.splats.spacing, o = scene.splats.origin - camera.eye;
    auto column = [&](int axis) { return glm::dvec2(sp[axis] * rx[axis], -sp[axis] * ry[axis]); };
    f.c = {0.5 * camera.width() + glm::dot(o, rx), 0.5 * camera.height() - glm::dot(o, ry)};
    f.colU = column(f.u);
    f.colV = column(f.v);
    f.invDet = 1.0 / (f.colU.x * f.colV.y - f.colU.y * f.colV.x);
    const glm::dvec2 colM = column(f.m);
    f.shear = {(f.colV.y * colM.x - f.colV.x * colM.y) * f.invDet,
               (f.colU.x * colM.y - f.colU.y * colM.x) * f.invDet};
    f.n = s.quality.factorisedSheets > 0 ? s.quality.factorisedSheets : kEdgeTileSamples;
    f.e = footprint::ellipticalFootprint(sp, camera.right * camera.pixelSize,
                                         -camera.up * camera.pixelSize, camera.view,
                                         scene.kernel.radius());
    f.r2Max = scene.table.r2Max();
    // The footprint's support in sheet coordinates: r^2 = x^T Q x, Q = J^T Q_screen J;
    // its bounding box has half extents R sqrt(Q^-1_uu), R sqrt(Q^-1_vv).
    const glm::dmat2 Qs(f.e.a, f.e.b, f.e.b, f.e.c), J(f.colU, f.colV);
    const glm::dmat2 Q = glm::transpose(J) * Qs * J;
    const double detQ = Q[0][0] * Q[1][1] - Q[0][1] * Q[1][0];
    const double R = std::sqrt(double(f.r2Max));
    const double hU = R * std::sqrt(Q[1][1] / detQ), hV = R * std::sqrt(Q[0][0] / detQ);
    f.dA = int(std::floor(-hU * f.n));
    f.dB = int(std::floor(-hV * f.n));
    f.stampW = (int(std::ceil(hU * f.n)) + 2 - f.dA + 7) / 8 * 8;
    f.stampH = int(std::ceil(hV * f.n)) + 2 - f.dB;
    // The grid's origin: the sheets' corner, one sample and the stamp before every voxel.
    const glm::ivec3 d = volume.dims;
    const double qEnd = double(d[f.m] - 1);
    f.U0 = std::min(0.0, f.shear.x * qEnd) - hU - 1.0 / f.n;
    f.V0 = std::min(0.0, f.shear.y * qEnd) - hV - 1.0 / f.n;
    const double U1 = double(d[f.u] - 1) + std::max(0.0, f.shear.x * qEnd) + hU + 1.0 / f.n;
    const double V1 = double(d[f.v] - 1) + std::max(0.0, f.shear.y * qEnd) + hV + 1.0 / f.n;
    // The window: the samples the warp reads (the screen's corners mapped back, a sample
    // more on each side), within the sheets' extent.
    double uLo = 1e300, uHi = -1e300, vLo = 1e300, vHi = -1e300;
    for (int k = 0; k < 4; ++k) {
        const glm::dvec2 p =
            f.sheet({k & 1 ? double(camera.width()) : 0.0, k & 2 ? double(camera.height()) : 0.0});
        uLo = std::min(uLo, p.x);
        uHi = std::max(uHi, p.x);
        vLo = std::min(vLo, p.y);
        vHi = std::max(vHi, p.y);
    }
    auto sample = [&](double x, double x0) { return (x - x0) * f.n; };
    f.a0 = int(std::floor(std::max(0.0, sample(uLo, f.U0)))) - 2;
    f.b0 = int(std::floor(std::max(0.0, sample(vLo, f.V0)))) - 2;
    const int a1 = int(std::ceil(std::min(sample(U1, f.U0), sample(uHi, f.U0)))) + 3;
    const int b1 = int(std::ceil(std::min(sample(V1, f.V0), sample(vHi, f.V0)))) + 3;
    f.width = std::max(0, a1 - f.a0);
    f.height = std::max(0, b1 - f.b0);
    return f;
}

/// Sheet q's place on the grid: voxel (u, v) at sample (n u + a, n v + b) + phase, and its
/// stamp as rows of the footprint's support only: row y (of stampH, from dB) covers columns
/// [x0[y], x0[y] + count[y]) (from dA; count even, its padding weighs 0) with weights from
/// w[offset[y]], each repeated four times to meet a sample's (tau, E_r, E_g, E_b). Columns
/// [xMin, xMax] and rows [yMin, yMax] hold every non-zero weight.
struct SheetStamp {
    int a, b;
    int xMin, xMax, yMin, yMax;
    std::vector<int> x0, count, offset;
    std::vector<int> samples;  ///< samples[y]: the samples of rows [0, y)
    std::vector<float> w;
};

SheetStamp sheetStamp(const Factorisation& f, int q, const footprint::FootprintTable& table) {
    const double sU = (f.shear.x * q - f.U0) * f.n, sV = (f.shear.y * q - f.V0) * f.n;
    SheetStamp st;
    st.a = int(std::floor(sU));
    st.b = int(std::floor(sV));
    const double phaseU = sU - st.a, phaseV = sV - st.b;
    st.xMin = f.stampW;
    st.xMax = -1;
    st.yMin = f.stampH;
    st.yMax = -1;
    std::vector<float> row(std::size_t(f.stampW) + 1);
    st.samples.push_back(0);
    for (int y = 0; y < f.stampH; ++y) {
        int lo = f.stampW, hi = -1;
        for (int x = 0; x < f.stampW; ++x) {
            // The sample's offset from the voxel centre, sheet units, then screen pixels.
            const double dU = (f.dA + x - phaseU) / f.n, dV = (f.dB + y - phaseV) / f.n;
            const glm::dvec2 p = f.colU * dU + f.colV * dV;
            const float r2 = f.e.r2(float(p.x), float(p.y));
            row[std::size_t(x)] = r2 < f.r2Max ? table.lookup(r2) * f.e.scale : 0.0f;
            if (row[std::size_t(x)] != 0.0f) {
                lo = std::min(lo, x);
                hi = x;
            }
        }
        row[std::size_t(f.stampW)] = 0.0f;
        const int count = hi < lo ? 0 : (hi - lo + 2) / 2 * 2;
        st.x0.push_back(hi < lo ? 0 : lo);
        st.count.push_back(count);
        st.offset.push_back(int(st.w.size()));
        st.samples.push_back(st.samples.back() + count);
        for (int x = 0; x < count; ++x) st.w.insert(st.w.end(), 4, row[std::size_t(lo + x)]);
        if (hi >= lo) {
            st.xMin = std::min(st.xMin, lo);
            st.xMax = std::max(st.xMax, hi);
            st.yMin = std::min(st.yMin, y);
            st.yMax = y;
        }
    }
    return st;
}

/// The factorised sheets' state per scene (Scene::Impl::state), made on first use: the list
/// in sheet order along i (a counting sort on the row (i, k); the list is in (k, j, i) order,
/// so a row stays in order of j): position p holds splat id[p] at (u, v) = (j = u[p], k), of
/// palette entry entry[p] (a paletted list); row v of slice q at positions
/// [row[q dims.z + v], row[q dims.z + v + 1]). Made once, so a frame with sheets along i
/// reads the list in sheet order without gathering it.
class SheetsAlongI {
  public:
    explicit SheetsAlongI(const Scene::Impl& scene) : scene_(scene) {}
    struct Order {
        std::vector<std::uint32_t> id, row;
        std::vector<std::uint16_t> u, entry;
    };
    const Order& get() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!order_) order_ = make();
        return *order_;
    }

  private:
    std::unique_ptr<Order> make() const {
        const SplatList& s = scene_.splats;
        auto o = std::make_unique<Order>();
        const std::size_t rows = std::size_t(scene_.volume->dims.z);
        o->row.assign(std::size_t(scene_.volume->dims.x) * rows + 1, 0);
        for (std::size_t n = 0; n < s.size(); ++n) ++o->row[s.i[n] * rows + s.k[n] + 1];
        for (std::size_t r = 1; r < o->row.size(); ++r) o->row[r] += o->row[r - 1];
        std::vector<std::uint32_t> next(o->row.begin(), o->row.end() - 1);
        o->id.resize(s.size());
        o->u.resize(s.size());
        if (s.paletted()) o->entry.resize(s.size());
        for (std::size_t n = 0; n < s.size(); ++n) {
            const std::uint32_t p = next[s.i[n] * rows + s.k[n]]++;
            o->id[p] = std::uint32_t(n);
            o->u[p] = s.j[n];
            if (s.paletted()) o->entry[p] = s.emissionIndex[n];
        }
        return o;
    }

    const Scene::Impl& scene_;
    std::mutex mutex_;
    std::unique_ptr<Order> order_;
};

/// A splat's (rho, e_r, e_g, e_b) at list position p through raw arrays (the per-splat loop
/// keeps them in registers): `id` maps positions to splats (null: the same), `entry` holds
/// the positions' palette entries (null: a list without palette, or shaded emission).
struct SplatValues {
    const SplatList& s;
    const std::uint32_t* id;
    const std::uint16_t* entry;
    const glm::vec4* palette;
    const float *er, *eg, *eb;
    glm::vec4 value(std::size_t p) const {
        if (entry) return palette[entry[p]];
        const std::size_t n = id ? id[p] : p;
        const glm::vec4 e = s.emission(n);
        return er ? glm::vec4(e.x, er[n], eg[n], eb[n]) : e;
    }
};

/// The positions' u, sorted within a row: u(p) and seek.
struct RowU {
    const std::uint16_t* at;
    int u(std::size_t p) const { return at[p]; }
    /// The first of positions [p, end) (the rest of a row whose last u is `last`) whose u is
    /// at least `u`. A row holds each u once, so u grows by at least 1 a position: the answer
    /// is at most u - u(p) positions after p and at most last - u before end - 1, which pins
    /// it in a row whose voxels are all splats and leaves the bisection a short stretch
    /// otherwise (it reads the row where the answer is, not its hidden middle).
    std::size_t seek(std::size_t p, std::size_t end, int last, int u) const {
        if (p >= end || at[p] >= u) return p;
        if (last < u) return end;
        const auto lo = std::max(std::ptrdiff_t(p) + 1, std::ptrdiff_t(end) - 1 - (last - u));
        const auto hi = std::min(std::ptrdiff_t(end) - 1, std::ptrdiff_t(p) + (u - at[p]));
        return std::size_t(std::lower_bound(at + lo, at + hi + 1, u) - at);
    }
};

/// The splats of row v of sheet q, list positions [first, second), by u, from one of two
/// sources. Sheets along j or k (ListRows): a row (k, j) of the list is consecutive
/// (CellIndex::cellStarts), read in place. Sheets along i (GatheredRows): the list in sheet
/// order (SheetsAlongI).
struct ListRows : RowU, SplatValues {
    const std::vector<std::uint32_t>& cells;
    std::size_t ny, cx;
    int m, rows;  ///< sheet axis (1 or 2), rows per sheet
    std::pair<std::size_t, std::size_t> range(int q, int v) const {
        const std::size_t k = std::size_t(m == 2 ? q : v), j = std::size_t(m == 2 ? v : q);
        const std::size_t c = (k * ny + j) * cx;
        return {cells[c], cells[c + cx]};
    }
};

struct GatheredRows : RowU, SplatValues {
    const std::vector<std::uint32_t>& row;
    int rows;
    std::pair<std::size_t, std::size_t> range(int q, int v) const {
        const std::size_t r = std::size_t(q) * std::size_t(rows) + std::size_t(v);
        return {row[r], row[r + 1]};
    }
};

/// A sheet row in brief: the u of its first and last splat and how many it holds (0: empty).
struct RowSpan {
    std::uint16_t lo = 0, hi = 0;
    std::uint32_t count = 0;
};

/// The rows' spans per sheet axis (Scene::Impl::state), each axis's made on its first frame
/// from the rows it reads (one pass over the rows, two list reads each): row v of sheet q at
/// q * rows + v. A band tests a sheet's rows against its opaque blocks from these alone, so a
/// hidden row costs neither the list's cache lines nor a bisection (rowHidden).
class SheetRowSpans {
  public:
    explicit SheetRowSpans(const Scene::Impl&) {}
    template <class Rows>
    const std::vector<RowSpan>& get(int m, int sheets, const Rows& list) {
        std::lock_guard<std::mutex> lock(mutex_);
        std::unique_ptr<std::vector<RowSpan>>& s = spans_[std::size_t(m)];
        if (!s) {
            s = std::make_unique<std::vector<RowSpan>>(std::size_t(sheets) *
                                                       std::size_t(list.rows));
            for (int q = 0; q < sheets; ++q)
                for (int v = 0; v < list.rows; ++v) {
                    const auto [p, end] = list.range(q, v);
                    if (p == end) continue;
                    RowSpan& r = (*s)[std::size_t(q) * std::size_t(list.rows) + std::size_t(v)];
                    r.lo = std::uint16_t(list.u(p));
                    r.hi = std::uint16_t(list.u(end - 1));
                    r.count = std::uint32_t(end - p);
                }
        }
        return *s;
    }

  private:
    std::mutex mutex_;
    std::unique_ptr<std::vector<RowSpan>> spans_[3];
};

/// The composited intermediate window: premultiplied colour and opacity, row-major.
struct Composited {
    std::vector<float> r, g, b, a;
};

/// Adds value * stamp rows [y0, y1) to the interleaved samples of the buffer, stamp row y
/// (SheetStamp::x0, count, offset) at `at` + (y - y0) `rowFloats` + its first column: `at` is
/// the stamp's column 0 in its row y0.
inline void addStampRowsScalar(float* at, std::size_t rowFloats, const SheetStamp& st, int y0,
                               int y1, const glm::vec4& value) {
    for (int y = y0; y < y1; ++y) {
        float* p = at + std::size_t(y - y0) * rowFloats + 4 * st.x0[std::size_t(y)];
        const float* w = &st.w[std::size_t(st.offset[std::size_t(y)])];
        for (int x = 0; x < 4 * st.count[std::size_t(y)]; ++x) p[x] += value[x & 3] * w[x];
    }
}

#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
/// addStampRowsScalar two samples (eight floats) at a time (every row's count is even).
inline void addStampRowsLanes(float* at, std::size_t rowFloats, const SheetStamp& st, int y0,
                              int y1, const glm::vec4& value) {
    const __m256 v =
        _mm256_setr_ps(value.x, value.y, value.z, value.w, value.x, value.y, value.z, value.w);
    for (int y = y0; y < y1; ++y) {
        float* p = at + std::size_t(y - y0) * rowFloats + 4 * st.x0[std::size_t(y)];
        const float* w = &st.w[std::size_t(st.offset[std::size_t(y)])];
        const int floats = 4 * st.count[std::size_t(y)];
        for (int x = 0; x < floats; x += 8)
            _mm256_storeu_ps(p + x,
                             _mm256_fmadd_ps(v, _mm256_loadu_ps(w + x), _mm256_loadu_ps(p + x)));
    }
}
FOOTPRINT_LANES_END
#endif

inline void addStampRows(float* at, std::size_t rowFloats, const SheetStamp& st, int y0, int y1,
                         const glm::vec4& value) {
#if defined(FOOTPRINT_HAVE_LANES)
    if (footprint::cpuHasLanes()) {
        addStampRowsLanes(at, rowFloats, st, y0, y1, value);
        return;
    }
#endif
    addStampRowsScalar(at, rowFloats, st, y0, y1, value);
}

/// A row of a band's sheet buffer, interleaved (tau, E_r, E_g, E_b) per sample, `row` at
/// window column 0: composites columns [c0, c1] into `out` (the window row starting at
/// `out0`; eight samples that are all zero make no change and are passed over), then clears
/// columns [x0, x1], in the same pass for the composited ones.
void compositeAndClear(float* row, int x0, int x1, int c0, int c1, std::size_t out0,
                       CompositeOrder order, Composited& out) {
    auto clear = [&](int from, int to) {  // columns [from, to)
        if (to > from)
            std::fill(row + 4 * std::ptrdiff_t(from), row + 4 * std::ptrdiff_t(to), 0.0f);
    };
    if (c1 < c0) {
        clear(x0, x1 + 1);
        return;
    }
    const std::size_t o = out0 + std::size_t(c0);
    compositeInterleavedRowAndClear(&out.r[o], &out.g[o], &out.b[o], &out.a[o], order, c1 - c0 + 1,
                                    row + 4 * std::ptrdiff_t(c0));
    clear(x0, c0);
    clear(c1 + 1, x1 + 1);
}

/// A band's state across sheets: the sheet buffer (interleaved tau, E_r, E_g, E_b per sample,
/// `stride` samples a row with `margin` samples before the window's column 0), the 8-column
/// blocks of the window the sheet has written and, front to back with early termination, those
/// whose every pixel is opaque.
struct BandBuffer {
    int row0, rows, margin, stride, width;
    std::vector<float> sheet;
    /// Per block of the window: a stamp of this sheet reached it.
    std::vector<std::uint8_t> written;
    std::vector<float> vals;  ///< a row of splat values (RowRun), zero between uses
    bool terminates;
    float threshold;
    std::vector<std::uint8_t> opaque;
    std::vector<int> nextOpen;  ///< per block, the first block at or after it that is not opaque
    std::vector<int> nextClosed;  ///< per block, the first opaque block at or after it
    int opaqueCount = 0;
    std::size_t weights = 0, hidden = 0;
    float* at(int y, int x) {
        return &sheet[4 * (std::size_t(y) * stride + std::size_t(x + margin))];
    }
    /// The first column at or after c0 in a block that is not opaque (past c1: all of
    /// [c0, c1] is hidden).
    int firstOpen(int c0) const {
        return std::max(c0, nextOpen[std::size_t(c0 / kBlock)] * kBlock);
    }
    /// The first column at or after c0 in an opaque block.
    int firstClosed(int c0) const {
        return std::max(c0, nextClosed[std::size_t(c0 / kBlock)] * kBlock);
    }
    /// The last column of the open stretch that holds column c (c in an open block).
    int openUntil(int c) const { return nextClosed[std::size_t(c / kBlock)] * kBlock - 1; }
    /// Notes columns [c0, c1] (their part in the window) as written.
    void markWritten(int c0, int c1) {
        c0 = std::max(c0, 0);
        c1 = std::min(c1, width - 1);
        if (c0 <= c1)
            std::fill(written.begin() + c0 / kBlock, written.begin() + c1 / kBlock + 1,
                      std::uint8_t(1));
    }
    /// Whether columns [c0, c1] within the window are all in opaque blocks (none: true).
    bool opaqueOver(int c0, int c1) const {
        c0 = std::max(c0, 0);
        c1 = std::min(c1, width - 1);
        return c0 > c1 || firstOpen(c0) > c1;
    }
};

/// The written rectangle of a band's sheet buffer: columns [x0, x1], band rows [y0, y1].
struct Written {
    int x0 = std::numeric_limits<int>::max(), x1 = -1, y0 = std::numeric_limits<int>::max(),
        y1 = -1;
};

/// One or two samples per voxel (n <= 2): a run of a sheet row's visible splats, voxels
/// [uLo, uHi] with their values at vals[4 (u + pad)] (zero between them), added to stamp rows
/// [ys, ye) at once as a convolution of the row with each stamp row (convolveRun).
struct RowRun {
    std::vector<float>& vals;
    int pad;
    int uLo = 0, uHi = -1;
    int first = 0, last = 0;  ///< the first and last voxel drawn in the row (addRowRuns)
    void put(int u, const glm::vec4& value) {
        if (uHi < uLo) uLo = u;
        uHi = u;
        float* p = &vals[4 * std::size_t(u + pad)];
        p[0] = value.x;
        p[1] = value.y;
        p[2] = value.z;
        p[3] = value.w;
    }
};

/// out[x] += sum over taps t with x - t = n u of w[t] vals[u], for outputs [x0, x1], in
/// increasing u per output (the order splat by splat stamping adds them in: the same image
/// bit for bit); `out` is the buffer row at the stamp row's column for u = 0.
inline void convolveRowScalar(float* out, const float* vals, const float* w, int taps, int n,
                              int x0, int x1) {
    for (int x = x0; x <= x1; ++x)
        for (int t = taps - 1; t >= 0; --t) {
            if ((x - t) % n != 0) continue;
            const int u = (x - t) / n;
            for (int c = 0; c < 4; ++c) out[4 * x + c] += w[4 * t] * vals[4 * u + c];
        }
}

#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
/// convolveRowScalar at n = 1, two outputs (eight floats) at a time; outputs past x1 gain
/// zeros. `Taps` > 0: that many taps, their weights held in registers across the row (a
/// stamp row has a handful); 0: `taps` of them, each weight read per output pair.
template <int Taps>
inline void convolveRowLanes(float* out, const float* vals, const float* w, int taps, int x0,
                             int x1) {
    if constexpr (Taps > 0) {
        // The voxel pairs (x - t, x - t + 1) of output pair x held in registers: two loads
        // per output pair instead of Taps.
        __m256 wt[Taps], vt[Taps];
        for (int t = 0; t < Taps; ++t) {
            wt[t] = _mm256_set1_ps(w[4 * t]);
            vt[t] = _mm256_loadu_ps(vals + 4 * (x0 - t));
        }
        for (int x = x0; x <= x1; x += 2) {
            __m256 acc = _mm256_loadu_ps(out + 4 * x);
            for (int t = Taps - 1; t >= 0; --t) acc = _mm256_fmadd_ps(wt[t], vt[t], acc);
            _mm256_storeu_ps(out + 4 * x, acc);
            for (int t = Taps - 1; t > 1; --t) vt[t] = vt[t - 2];
            if constexpr (Taps > 1) vt[1] = _mm256_loadu_ps(vals + 4 * (x + 1));
            vt[0] = _mm256_loadu_ps(vals + 4 * (x + 2));
        }
    } else {
        for (int x = x0; x <= x1; x += 2) {
            __m256 acc = _mm256_loadu_ps(out + 4 * x);
            for (int t = taps - 1; t >= 0; --t)
                acc = _mm256_fmadd_ps(_mm256_set1_ps(w[4 * t]), _mm256_loadu_ps(vals + 4 * (x - t)),
                                      acc);
            _mm256_storeu_ps(out + 4 * x, acc);
        }
    }
}

/// convolveRowScalar at n = 2 (x0 even), outputs 2m and 2m + 1 at a time: both take voxel
/// m - k through taps 2k and 2k + 1, which are the stamp's interleaved weights w[8k, 8k + 8).
/// `Pairs` > 0: taps = 2 Pairs, the weights held in registers; 0: any even `taps`.
template <int Pairs>
inline void convolvePairsLanes(float* out, const float* vals, const float* w, int taps, int x0,
                               int x1) {
    auto voxel = [&](int u) {
        return _mm256_broadcast_ps(reinterpret_cast<const __m128*>(vals + 4 * u));
    };
    if constexpr (Pairs > 0) {
        // The voxels m - k of output pair m held in registers, each loaded once per row.
        __m256 wk[Pairs], vk[Pairs];
        for (int k = 0; k < Pairs; ++k) {
            wk[k] = _mm256_loadu_ps(w + 8 * k);
            vk[k] = voxel(x0 / 2 - k);
        }
        for (int x = x0; x <= x1; x += 2) {
            __m256 acc = _mm256_loadu_ps(out + 4 * x);
            for (int k = Pairs - 1; k >= 0; --k) acc = _mm256_fmadd_ps(wk[k], vk[k], acc);
            _mm256_storeu_ps(out + 4 * x, acc);
            for (int k = Pairs - 1; k > 0; --k) vk[k] = vk[k - 1];
            vk[0] = voxel(x / 2 + 1);
        }
    } else {
        for (int x = x0; x <= x1; x += 2) {
            __m256 acc = _mm256_loadu_ps(out + 4 * x);
            const int m = x / 2;
            for (int k = taps / 2 - 1; k >= 0; --k)
                acc = _mm256_fmadd_ps(_mm256_loadu_ps(w + 8 * k), voxel(m - k), acc);
            _mm256_storeu_ps(out + 4 * x, acc);
        }
    }
}

/// The convolution of one stamp row (n = 1 or 2) by a kernel specialised to its tap count.
using ConvolveLanes = void (*)(float*, const float*, const float*, int, int, int);

ConvolveLanes convolveLanes(int n, int taps) {
    static constexpr ConvolveLanes row[] = {
        convolveRowLanes<0>, convolveRowLanes<1>, convolveRowLanes<2>,  convolveRowLanes<3>,
        convolveRowLanes<4>, convolveRowLanes<5>, convolveRowLanes<6>,  convolveRowLanes<7>,
        convolveRowLanes<8>, convolveRowLanes<9>, convolveRowLanes<10>, convolveRowLanes<11>,
        convolveRowLanes<12>};
    static constexpr ConvolveLanes pairs[] = {
        convolvePairsLanes<0>, convolvePairsLanes<1>, convolvePairsLanes<2>,
        convolvePairsLanes<3>, convolvePairsLanes<4>, convolvePairsLanes<5>,
        convolvePairsLanes<6>, convolvePairsLanes<7>, convolvePairsLanes<8>};
    if (n == 1) return taps < 13 ? row[taps] : row[0];
    return taps / 2 < 9 ? pairs[taps / 2] : pairs[0];
}
FOOTPRINT_LANES_END
#endif

/// Adds a run's splats' stamp rows [ys, ye) (stamp row 0 at band row `row`; column 0 of voxel
/// u at col0 + n u), then clears its values.
void convolveRun(RowRun& run, const SheetStamp& st, int n, int row, int ys, int ye, int col0,
                 BandBuffer& band) {
    // The rows' columns, each past its last weight by at most two (a padded tap, a pair's
    // second output), which gain zeros.
    band.markWritten(col0 + n * run.uLo + st.xMin, col0 + n * run.uHi + st.xMax + 2);
    const float* vals = &run.vals[4 * std::size_t(run.pad)];
    for (int y = ys; y < ye; ++y) {
        const int taps = st.count[std::size_t(y)], base = col0 + st.x0[std::size_t(y)];
        if (taps == 0) continue;
        float* out = band.at(row + y, base);
        const float* w = &st.w[std::size_t(st.offset[std::size_t(y)])];
        const int x0 = n * run.uLo, x1 = n * run.uHi + taps - 1;
#if defined(FOOTPRINT_HAVE_LANES)
        if (footprint::cpuHasLanes()) {
            convolveLanes(n, taps)(out, vals, w, taps, x0, x1);
            continue;
        }
#endif
        convolveRowScalar(out, vals, w, taps, n, x0, x1);
    }
    std::fill(run.vals.begin() + 4 * std::ptrdiff_t(run.uLo + run.pad),
              run.vals.begin() + 4 * std::ptrdiff_t(run.uHi + run.pad + 1), 0.0f);
    run.uHi = run.uLo - 1;
}

/// Where a sheet row's stamps go in a band: stamp row 0 at band row `row`, stamp rows
/// [ys, ye) inside the band, column 0 of voxel u's stamp at col0 + n u.
struct RowPlace {
    int row, ys, ye, col0;
};

inline int floorDiv(int x, int y) { return x >= 0 ? x / y : -((-x + y - 1) / y); }

/// One or two samples per voxel: adds the visible splats of list positions [p, pEnd) (one
/// sheet row) as runs (convolveRun) and returns how many; run.first, run.last: the first and
/// last drawn voxel. Front to back with early termination, a splat is hidden when the stamp's
/// box (not only its support) is over opaque blocks: testing the support alone culls a few
/// per cent more at no measurable saving and composites less into nearly opaque edges (ch2 at
/// 512², early termination 1/32: RMSE 2.6e-3 against 2.4e-3 at azimuth 120°). The splats are
/// taken by stretches of open blocks: every splat whose box ends in or past a stretch's first
/// column and starts in it is visible, without a test of its own; hidden ones are skipped by
/// bisection (a row is sorted by u).
template <class Rows>
std::size_t addRowRuns(const Factorisation& f, const Rows& list, std::size_t p, std::size_t pEnd,
                       int uLast, const SheetStamp& st, RowPlace at, RowRun& run,
                       BandBuffer& band) {
    const int n = f.n, box = f.stampW - 1;
    // Columns of the splats inside the window: hi = col + xMax >= 0, lo = col + xMin < width.
    const int colLo = -st.xMax, colHi = f.width - 1 - st.xMin;
    std::size_t drawn = 0;
    while (p < pEnd) {
        int col = n * list.u(p) + at.col0;
        int end = colHi;  // the last column of the visible stretch
        if (col < colLo) {
            p = list.seek(p + 1, pEnd, uLast, floorDiv(colLo - at.col0 + n - 1, n));
            continue;
        }
        if (col > colHi) break;
        if (band.terminates) {
            const int open = band.firstOpen(std::max(col, 0));
            if (open > std::min(col + box, f.width - 1)) {
                // On to the first splat whose box reaches the open block.
                const std::size_t next =
                    list.seek(p + 1, pEnd, uLast, floorDiv(open - box - at.col0 + n - 1, n));
                band.hidden += next - p;
                p = next;
                continue;
            }
            end = std::min(end, band.openUntil(open));
        }
        if (drawn == 0) run.first = list.u(p);
        for (; p < pEnd; ++p) {
            const int u = list.u(p);
            col = n * u + at.col0;
            if (col > end) break;
            if (run.uHi >= run.uLo && u > run.uHi + f.stampW)
                convolveRun(run, st, n, at.row, at.ys, at.ye, at.col0, band);
            run.put(u, list.value(p));
            run.last = u;
            ++drawn;
        }
    }
    if (run.uHi >= run.uLo) convolveRun(run, st, n, at.row, at.ys, at.ye, at.col0, band);
    return drawn;
}

/// Asks the cache for rows [vLo, vHi] of sheet q (their u and palette entries, up to 4 KiB of
/// each), which the band reads next: a band reads each sheet's rows as one short stretch of
/// the list, which the processor's stream prefetch finds only after its first misses.
template <class Rows>
void prefetchRows(const Rows& list, int q, int vLo, int vHi) {
    const std::size_t p0 = list.range(q, vLo).first, p1 = list.range(q, vHi).second;
    const std::size_t end = std::min(p1, p0 + 2048);
    for (std::size_t p = p0; p < end; p += 32) {
        __builtin_prefetch(list.at + p);
        if (list.entry) __builtin_prefetch(list.entry + p);
    }
}

/// Sheet q's voxel rows [vLo, vHi] whose stamp rows meet the band: row v's stamp row 0 at
/// band row n v + top, column 0 of voxel u's stamp at n u + col0.
struct SheetRows {
    int vLo, vHi, top, col0;
};

SheetRows sheetRows(const Factorisation& f, const SheetStamp& st, const BandBuffer& band,
                    int rows) {
    const int n = f.n;
    const int top = st.b + f.dB - f.b0 - band.row0;
    return {std::max(0, -floorDiv(top + st.yMax, n)),
            std::min(floorDiv(band.rows - 1 - top - st.yMin, n), rows - 1), top,
            st.a + f.dA - f.a0};
}

/// Whether a sheet row with splats from u = lo to hi adds nothing to the band, front to back
/// with early termination: the columns of their stamps' boxes (stampW from n u + col0) are
/// all over opaque blocks or outside the window, so each splat would be skipped as hidden by
/// the test of addRowRuns (the same blocks, per splat); and opacity only grows, so what is
/// hidden stays hidden until the band ends.
bool rowHidden(const Factorisation& f, const SheetRows& r, const BandBuffer& band, int lo, int hi) {
    return band.opaqueOver(f.n * lo + r.col0, f.n * hi + r.col0 + f.stampW - 1);
}

/// Whether sheet q's rows `r` add nothing to the band (from their spans, `spans` at the
/// sheet's row 0, without reading the list): they hold no splat, or front to back with early
/// termination their splats together are hidden (rowHidden of the rows' joint span). `hidden`
/// gains their splats when they are hidden.
bool sheetAddsNothing(const Factorisation& f, const SheetRows& r, const RowSpan* spans,
                      const BandBuffer& band, std::size_t& hidden) {
    int lo = std::numeric_limits<int>::max(), hi = -1;
    std::size_t splats = 0;
    for (int v = r.vLo; v <= r.vHi; ++v) {
        const RowSpan& s = spans[v];
        if (s.count == 0) continue;
        lo = std::min(lo, int(s.lo));
        hi = std::max(hi, int(s.hi));
        splats += s.count;
    }
    if (splats == 0) return true;
    if (!band.terminates || !rowHidden(f, r, band, lo, hi)) return false;
    hidden += splats;
    return true;
}

/// prefetchRows from the rows' spans (`spans` at sheet q's row 0): of each row of sheet q that
/// is neither empty nor hidden (rowHidden), the lines of its first and last splats (where a
/// row's visible splats are once opaque blocks cover its middle, which seek passes over
/// unread), and the rest of the row while the band has no opaque block under it, up to 2048
/// positions of the list in all.
template <class Rows>
void prefetchSheetRows(const Factorisation& f, const Rows& list, int q, const SheetRows& r,
                       const RowSpan* spans, const BandBuffer& band) {
    auto line = [&](std::size_t p) {
        __builtin_prefetch(list.at + p);
        if (list.entry) __builtin_prefetch(list.entry + p);
    };
    std::size_t budget = 2048;
    for (int v = r.vLo; v <= r.vHi; ++v) {
        const RowSpan& s = spans[v];
        if (s.count == 0) continue;
        const int c0 = std::max(f.n * s.lo + r.col0, 0);
        const int c1 = std::min(f.n * s.hi + r.col0 + f.stampW - 1, f.width - 1);
        if (c0 > c1 || (band.terminates && band.firstOpen(c0) > c1)) continue;  // rowHidden
        const auto [p, end] = list.range(q, v);
        line(p);
        line(end - 1);
        if (budget < end - p || (band.terminates && band.firstClosed(c0) <= c1)) continue;
        for (std::size_t x = p + 32; x < end - 1; x += 32) line(x);
        budget -= end - p;
    }
}

/// Adds the stamps of sheet q's splats that meet the band into its buffer. Front to back with
/// early termination, a splat is skipped when the blocks under its stamp's box (stampW
/// columns, wider than the footprint's support) are all opaque: testing the support alone
/// culls a few per cent more at no measurable saving and composites less into nearly opaque
/// edges (ch2 at 512², early termination 1/32: RMSE 2.6e-3 against 2.4e-3 at azimuth 120°).
/// One or two samples per voxel add a row's runs of splats as convolutions (convolveRun), more
/// samples add splat by splat (addStampRows). `spans` (the sheet's rows' spans, or null)
/// passes over the rows that hold no splat or are hidden whole (rowHidden) before reading them.
template <class Rows>
Written addSheet(const Factorisation& f, const Rows& list, int q, const SheetStamp& st,
                 const RowSpan* spans, BandBuffer& band) {
    const int n = f.n;
    const SheetRows rows = sheetRows(f, st, band, list.rows);
    const int vLo = rows.vLo, vHi = rows.vHi, col0 = rows.col0;
    RowRun run{band.vals, f.stampW + 2};
    Written w;
    for (int v = vLo; v <= vHi; ++v) {
        if (spans) {
            const RowSpan& s = spans[v];
            if (s.count == 0) continue;
            if (band.opaqueCount > 0 && rowHidden(f, rows, band, s.lo, s.hi)) {
                band.hidden += s.count;
                continue;
            }
        }
        const auto [pFirst, pEnd] = list.range(q, v);
        if (pFirst == pEnd) continue;
        const int uLast = spans ? spans[v].hi : list.u(pEnd - 1);  // the row's last splat
        const int row = n * v + rows.top;                          // stamp row 0, band rows
        const int ys = std::max(st.yMin, -row), ye = std::min(st.yMax + 1, band.rows - row);
        std::size_t drawn = 0;
        int first = std::numeric_limits<int>::max(), last = -1;  // columns of the drawn
        if (n <= 2) {
            drawn = addRowRuns(f, list, pFirst, pEnd, uLast, st, RowPlace{row, ys, ye, col0}, run,
                               band);
            if (drawn) {
                first = n * run.first + col0 + st.xMin;
                last = n * run.last + col0 + st.xMax;
            }
        } else {
            for (std::size_t p = pFirst; p < pEnd; ++p) {
                const int u = list.u(p), col = n * u + col0;
                const int lo = col + st.xMin, hi = col + st.xMax;
                if (hi < 0 || lo >= f.width) continue;
                if (band.terminates) {
                    const int open = band.firstOpen(std::max(col, 0));
                    if (open > std::min(col + f.stampW - 1, f.width - 1)) {
                        const std::size_t next = list.seek(
                            p + 1, pEnd, uLast, floorDiv(open - (f.stampW - 1) - col0 + n - 1, n));
                        band.hidden += next - p;
                        p = next - 1;
                        continue;
                    }
                }
                addStampRows(band.at(row + ys, col), 4 * std::size_t(band.stride), st, ys, ye,
                             list.value(p));
                band.markWritten(lo, hi + 1);
                ++drawn;
                first = std::min(first, lo);
                last = hi;
            }
        }
        if (drawn == 0) continue;
        band.weights +=
            drawn * std::size_t(st.samples[std::size_t(ye)] - st.samples[std::size_t(ys)]);
        w.x0 = std::min(w.x0, first);
        w.x1 = std::max(w.x1, last);
        w.y0 = std::min(w.y0, row + ys);
        w.y1 = std::max(w.y1, row + ye - 1);
    }
    return w;
}

/// Composites the sheet's written rectangle `w` of the band's buffer into `out` and clears it:
/// in the window, the stretches of written blocks only (compositeAndClear; the blocks between
/// hold zeros, which would make no change, so a row whose visible splats are at its two ends
/// is not composited across its hidden middle); outside it, clears what stamps wrote there.
void compositeSheet(const Factorisation& f, const Written& w, CompositeOrder order, Composited& out,
                    BandBuffer& band) {
    const int c0 = std::max(w.x0, 0), c1 = std::min(w.x1, f.width - 1);
    for (int y = w.y0; y <= w.y1; ++y) {
        float* row = band.at(y, 0);
        if (w.x0 < 0) std::fill(row + 4 * w.x0, row + 4 * std::min(0, w.x1 + 1), 0.0f);
        if (w.x1 >= f.width)
            std::fill(row + 4 * std::max(f.width, w.x0), row + 4 * (w.x1 + 1), 0.0f);
    }
    if (c1 < c0) return;
    const int bEnd = c1 / kBlock;
    for (int b = c0 / kBlock; b <= bEnd; ++b) {
        if (!band.written[std::size_t(b)]) continue;
        int e = b;
        while (e < bEnd && band.written[std::size_t(e) + 1]) ++e;
        const int s0 = std::max(b * kBlock, c0), s1 = std::min(e * kBlock + kBlock - 1, c1);
        for (int y = w.y0; y <= w.y1; ++y)
            compositeAndClear(band.at(y, 0), s0, s1, s0, s1, std::size_t(band.row0 + y) * f.width,
                              order, out);
        b = e;
    }
}

/// Marks the blocks of columns [c0, c1] whose every pixel of the band is now opaque (of those
/// the sheet wrote: the others are as they were).
void markOpaqueBlocks(const Factorisation& f, const Composited& out, int c0, int c1,
                      BandBuffer& band) {
    bool marked = false;
    for (int b = c0 / kBlock; b <= c1 / kBlock; ++b) {
        if (band.opaque[std::size_t(b)] || !band.written[std::size_t(b)]) continue;
        bool all = true;
        const int xe = std::min(f.width, (b + 1) * kBlock);
        for (int y = 0; y < band.rows && all; ++y)
            for (int x = b * kBlock; x < xe; ++x)
                if (out.a[std::size_t(band.row0 + y) * f.width + std::size_t(x)] < band.threshold) {
                    all = false;
                    break;
                }
        if (all) {
            band.opaque[std::size_t(b)] = 1;
            ++band.opaqueCount;
            marked = true;
        }
    }
    if (!marked) return;
    for (int b = int(band.opaque.size()) - 1; b >= 0; --b) {
        const std::size_t k = std::size_t(b);
        band.nextOpen[k] = band.opaque[k] ? band.nextOpen[k + 1] : b;
        band.nextClosed[k] = band.opaque[k] ? b : band.nextClosed[k + 1];
    }
}

/// One band of the window, rows [row0, row0 + rows): every sheet in visiting order, its
/// splats' stamps added into the band's sheet buffer, then composited into `out` by its
/// written blocks (compositeSheet). Front to back, the band passes over the sheets and rows
/// its opaque blocks hide whole, as their spans tell (`rowSpans`: sheetAddsNothing, addSheet),
/// and ends when all its column blocks are opaque. Returns the samples added and the splats
/// skipped as hidden.
template <class Rows>
std::pair<std::size_t, std::size_t> renderBand(const Factorisation& f, const Rows& list, int sheets,
                                               const std::vector<SheetStamp>& stamps,
                                               const std::vector<RowSpan>& rowSpans, int row0,
                                               int rows, CompositeOrder order,
                                               double earlyTermination, Composited& out) {
    BandBuffer band;
    band.row0 = row0;
    band.rows = rows;
    band.margin = f.stampW;
    band.stride = f.width + 2 * f.stampW + 8;
    band.sheet.assign(4 * std::size_t(band.stride) * std::size_t(rows), 0.0f);
    if (f.n <= 2)
        band.vals.assign(4 * (std::size_t(f.rowLength) + 2 * std::size_t(f.stampW) + 8), 0.0f);
    band.terminates = order == CompositeOrder::FrontToBack && earlyTermination > 0;
    band.threshold = float(1.0 - earlyTermination);
    const int blocks = (f.width + kBlock - 1) / kBlock;
    band.width = f.width;
    band.written.assign(std::size_t(blocks), 0);
    band.opaque.assign(std::size_t(blocks), 0);
    band.nextOpen.resize(std::size_t(blocks) + 1);
    for (int b = 0; b <= blocks; ++b) band.nextOpen[std::size_t(b)] = b;
    band.nextClosed.assign(std::size_t(blocks) + 1, blocks);
    // The test's switch off: every row read, every written rectangle composited whole.
    const bool skip = detail::factorisedSheetsSkipHidden.load(std::memory_order_relaxed);
    const RowSpan* spans = skip ? rowSpans.data() : nullptr;
    auto sheetSpans = [&](int q) {
        return spans ? spans + std::size_t(q) * std::size_t(list.rows) : nullptr;
    };
    for (int k = 0; k < sheets && !(band.terminates && band.opaqueCount == blocks); ++k) {
        const int q = f.ascending ? k : sheets - 1 - k;
        // Until a block is opaque nothing is hidden: the rows are read as they come.
        const bool hiding = spans && band.opaqueCount > 0;
        if (hiding && sheetAddsNothing(f, sheetRows(f, stamps[std::size_t(q)], band, list.rows),
                                       sheetSpans(q), band, band.hidden))
            continue;
        // The next sheet's rows asked for while this one's are added (prefetchRows).
        if (const int next = f.ascending ? q + 1 : q - 1; k + 1 < sheets) {
            const SheetRows r = sheetRows(f, stamps[std::size_t(next)], band, list.rows);
            if (hiding && r.vLo <= r.vHi)
                prefetchSheetRows(f, list, next, r, sheetSpans(next), band);
            else if (r.vLo <= r.vHi)
                prefetchRows(list, next, r.vLo, r.vHi);
        }
        const Written w = addSheet(f, list, q, stamps[std::size_t(q)], sheetSpans(q), band);
        if (w.x1 < w.x0) continue;
        if (!skip) band.markWritten(w.x0, w.x1);
        compositeSheet(f, w, order, out, band);
        const int c0 = std::max(w.x0, 0), c1 = std::min(w.x1, f.width - 1);
        if (c1 < c0) continue;
        if (band.terminates) markOpaqueBlocks(f, out, c0, c1, band);
        std::fill(band.written.begin() + c0 / kBlock, band.written.begin() + c1 / kBlock + 1,
                  std::uint8_t(0));
    }
    return {band.weights, band.hidden};
}

/// Catmull-Rom weights of the four samples around a point t in [0, 1) past the second.
inline void catmullRom(float t, float (&w)[4]) {
    w[0] = ((-t + 2.0f) * t - 1.0f) * t * 0.5f;
    w[1] = ((3.0f * t - 5.0f) * t * t + 2.0f) * 0.5f;
    w[2] = ((-3.0f * t + 4.0f) * t + 1.0f) * t * 0.5f;
    w[3] = (t - 1.0f) * t * t * 0.5f;
}

/// A pixel's Catmull-Rom taps on the window: the 4 x 4 samples from `o` (its top-left) with
/// weights wa (along a row) and wb (across rows).
struct WarpTaps {
    std::size_t o;
    float wa[4], wb[4];
    double ga, gb;  ///< the pixel centre in window samples (for warpError)
};

/// The taps of the pixel centre (x + 1/2, y + 1/2); false when they leave the window.
bool warpTaps(const Factorisation& f, int x, int y, WarpTaps& t) {
    const glm::dvec2 p = f.sheet({x + 0.5, y + 0.5});
    const double ga = (p.x - f.U0) * f.n - f.a0, gb = (p.y - f.V0) * f.n - f.b0;
    const double fa = std::floor(ga), fb = std::floor(gb);
    if (!(fa >= 1 && fb >= 1 && fa + 2 < f.width && fb + 2 < f.height)) return false;
    t.ga = ga;
    t.gb = gb;
    catmullRom(float(ga - fa), t.wa);
    catmullRom(float(gb - fb), t.wb);
    t.o = (std::size_t(fb) - 1) * std::size_t(f.width) + std::size_t(fa) - 1;
    return true;
}

/// Opacity clamped to [0, 1] and colour to [0, opacity] (the spline's overshoot at opaque
/// edges).
inline glm::vec4 clampWarped(const glm::vec4& sum) {
    const float a = std::clamp(sum.a, 0.0f, 1.0f);
    return {std::clamp(sum.r, 0.0f, a), std::clamp(sum.g, 0.0f, a), std::clamp(sum.b, 0.0f, a), a};
}

/// The spline's sum at one pixel: rows of four taps, then the four rows, each a product then
/// a sum (the order warpPairLanes keeps).
/// The sum over the 4 x 4 samples from `o`, `step` apart along a row and `rowStep` across
/// rows, with weights wa along a row and wb across rows.
glm::vec4 splineSum(const glm::vec4* rgba, std::size_t o, std::size_t step, std::size_t rowStep,
                    const float (&wa)[4], const float (&wb)[4]) {
    glm::vec4 sum(0.0f);
    for (int j = 0; j < 4; ++j) {
        const std::size_t r = o + std::size_t(j) * rowStep;
        glm::vec4 row(0.0f);
        for (int i = 0; i < 4; ++i) row += wa[i] * rgba[r + std::size_t(i) * step];
        sum += wb[j] * row;
    }
    return sum;
}

glm::vec4 warpSum(const glm::vec4* rgba, std::size_t width, const WarpTaps& t) {
    return splineSum(rgba, t.o, 1, width, t.wa, t.wb);
}

#if defined(FOOTPRINT_HAVE_LANES)
/// warpSum of two pixels at once, one per half of eight lanes: each half takes warpSum's
/// products and sums in its order, compiled for AVX without FMA (a fused multiply-add would
/// round once where warpSum rounds twice), so the pixels are warpSum's bit for bit.
__attribute__((target("avx"))) void warpPairLanes(const glm::vec4* rgba, std::size_t width,
                                                  const WarpTaps& t0, const WarpTaps& t1,
                                                  glm::vec4& s0, glm::vec4& s1) {
    const float* base = reinterpret_cast<const float*>(rgba);
    __m256 sum = _mm256_setzero_ps();
    for (int j = 0; j < 4; ++j) {
        const float* r0 = base + 4 * (t0.o + std::size_t(j) * width);
        const float* r1 = base + 4 * (t1.o + std::size_t(j) * width);
        __m256 row = _mm256_setzero_ps();
        for (int i = 0; i < 4; ++i) {
            const __m256 wa = _mm256_set_m128(_mm_set1_ps(t1.wa[i]), _mm_set1_ps(t0.wa[i]));
            row = _mm256_add_ps(row, _mm256_mul_ps(wa, _mm256_loadu2_m128(r1 + 4 * i, r0 + 4 * i)));
        }
        const __m256 wb = _mm256_set_m128(_mm_set1_ps(t1.wb[j]), _mm_set1_ps(t0.wb[j]));
        sum = _mm256_add_ps(sum, _mm256_mul_ps(wb, row));
    }
    _mm_storeu_ps(&s0.x, _mm256_castps256_ps128(sum));
    _mm_storeu_ps(&s1.x, _mm256_extractf128_ps(sum, 1));
}
#endif

/// The warp's error at the pixel of taps `t`, estimated: the spline through every other
/// sample of the window (spacing 2 / n voxels) against `fine`, the spline through every
/// sample (warpSum of `t`).
/// Where the image is smooth the spline's error is of order h^3, so the coarse one's is 8
/// times the fine one's and their difference over 7 is the fine one's; at an edge sharper
/// than the samples both are wrong by a fraction of the edge and the estimate is large. The
/// largest over the premultiplied channels; a pixel too near the window's edge for the coarse
/// taps is estimated by the largest change between its fine taps.
float warpError(const Factorisation& f, const glm::vec4* rgba, const WarpTaps& t,
                const glm::vec4& fine) {
    const std::size_t width = std::size_t(f.width);
    const double ca = 0.5 * t.ga, cb = 0.5 * t.gb;
    const double fa = std::floor(ca), fb = std::floor(cb);
    glm::vec4 d;
    if (fa >= 1 && fb >= 1 && 2 * (fa + 2) < f.width && 2 * (fb + 2) < f.height) {
        float wa[4], wb[4];
        catmullRom(float(ca - fa), wa);
        catmullRom(float(cb - fb), wb);
        const std::size_t o = 2 * ((std::size_t(fb) - 1) * width + std::size_t(fa) - 1);
        d = glm::abs(splineSum(rgba, o, 2, 2 * width, wa, wb) - fine) / 7.0f;
    } else {
        glm::vec4 lo(1e30f), hi(-1e30f);
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const glm::vec4& v = rgba[t.o + std::size_t(j) * width + std::size_t(i)];
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
        d = hi - lo;
    }
    return std::max(std::max(d.x, d.y), std::max(d.z, d.w));
}

/// The screen image: the composited window at each pixel centre, by the Catmull-Rom spline
/// through its samples (warpSum, two pixels at a time where the lanes are), clamped
/// (clampWarped). With `edges`, also flags (1) pixels whose estimated warp error (warpError)
/// is above `tolerance`, at least one in each row of each `tile`-pixel screen tile that holds
/// such a pixel (after one, the rest of the tile's row is not tested); pixels outside the
/// window are never flagged (no splat reaches them).
Image warp(const Factorisation& f, const Composited& w, int width, int height,
           std::vector<std::uint8_t>* edges, float tolerance, int tile) {
    // The window as one (r, g, b, a) per sample: a tap is one load.
    std::vector<glm::vec4> rgba(w.r.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rgba.size(), 16384),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t k = r.begin(); k != r.end(); ++k)
                              rgba[k] = glm::vec4(w.r[k], w.g[k], w.b[k], w.a[k]);
                      });
    Image image(width, height);
    const std::size_t rowSamples = std::size_t(f.width);
#if defined(FOOTPRINT_HAVE_LANES)
    const bool lanes = footprint::cpuHasLanes();
#else
    const bool lanes = false;
#endif
    if (edges) edges->assign(std::size_t(width) * std::size_t(height), 0);
    tbb::parallel_for(0, height, [&](int y) {
        WarpTaps t0, t1;
        int flaggedTile = -1;  // the tile of this row flagged last
        const auto test = [&](int x, const WarpTaps& t, const glm::vec4& sum) {
            if (!edges || x / tile == flaggedTile) return;
            if (warpError(f, rgba.data(), t, sum) > tolerance) {
                (*edges)[std::size_t(y) * std::size_t(width) + std::size_t(x)] = 1;
                flaggedTile = x / tile;
            }
        };
        for (int x = 0; x < width; ++x) {
            if (!warpTaps(f, x, y, t0)) continue;
#if defined(FOOTPRINT_HAVE_LANES)
            if (lanes && x + 1 < width && warpTaps(f, x + 1, y, t1)) {
                glm::vec4 s0, s1;
                warpPairLanes(rgba.data(), rowSamples, t0, t1, s0, s1);
                image.at(x, y) = clampWarped(s0);
                image.at(x + 1, y) = clampWarped(s1);
                test(x, t0, s0);
                test(++x, t1, s1);
                continue;
            }
#endif
            const glm::vec4 sum = warpSum(rgba.data(), rowSamples, t0);
            image.at(x, y) = clampWarped(sum);
            test(x, t0, sum);
        }
    });
    return image;
}

}  // namespace

bool factorisedSheetsApply(const Camera& camera, const RenderSettings& s, bool labels, bool clipped,
                           double lowPass, int level) {
    return (s.quality.factorisedSheets > 0 || s.quality.warpTolerance > 0) &&
           s.renderer == RendererKind::Axis &&
           !camera.perspective() && s.mode == RenderMode::Dvr &&
           s.classification == Classification::Pre && !labels && !clipped && !(lowPass > 0) &&
           level == 0;
}

Image renderFactorisedSheets(const Scene::Impl& scene, const Camera& camera,
                             const RenderSettings& s, const float* er, const float* eg,
                             const float* eb, RenderStats& stats,
                             std::vector<std::uint8_t>* edges) {
    const auto start = Clock::now();
    const Factorisation f = factorise(scene, camera, s);
    const glm::ivec3 dims = scene.volume->dims;
    const int sheets = dims[f.m];
    // Sheets along i cross the list's rows: read in the scene's sheet order; others in place.
    static const SheetsAlongI::Order none;
    const SheetsAlongI::Order& alongI = f.m == 0 ? scene.state<SheetsAlongI>().get() : none;
    const SplatList& list = scene.splats;
    const bool palette = list.paletted() && !er;
    const GatheredRows gatheredRows{
        {alongI.u.data()},
        {list, alongI.id.data(), palette ? alongI.entry.data() : nullptr, list.palette.data(), er,
         eg, eb},
        alongI.row,
        dims[f.v]};
    CellIndex& cells = scene.state<CellIndex>();
    const ListRows listRows{{list.i.data()},
                            {list, nullptr, palette ? list.emissionIndex.data() : nullptr,
                             list.palette.data(), er, eg, eb},
                            cells.cellStarts(),
                            std::size_t(dims.y),
                            std::size_t(cells.cellsX()),
                            f.m,
                            dims[f.v]};
    SheetRowSpans& rowSpans = scene.state<SheetRowSpans>();
    const std::vector<RowSpan>& spans =
        f.m == 0 ? rowSpans.get(0, sheets, gatheredRows) : rowSpans.get(f.m, sheets, listRows);
    std::vector<SheetStamp> stamps(static_cast<std::size_t>(sheets));
    tbb::parallel_for(0, sheets,
                      [&](int q) { stamps[std::size_t(q)] = sheetStamp(f, q, scene.table); });
    stats.orderMs = msSince(start);
    const auto tiles = Clock::now();
    Composited w;
    const std::size_t size = std::size_t(f.width) * std::size_t(f.height);
    w.r.assign(size, 0.0f);
    w.g.assign(size, 0.0f);
    w.b.assign(size, 0.0f);
    w.a.assign(size, 0.0f);
    const int bands = (f.height + kBand - 1) / kBand;
    std::vector<std::pair<std::size_t, std::size_t>> counts(static_cast<std::size_t>(bands));
    tbb::parallel_for(0, bands, [&](int k) {
        const int row0 = k * kBand, rows = std::min(kBand, f.height - row0);
        counts[std::size_t(k)] = f.m == 0
                                     ? renderBand(f, gatheredRows, sheets, stamps, spans, row0,
                                                  rows, s.order, s.quality.earlyTermination, w)
                                     : renderBand(f, listRows, sheets, stamps, spans, row0, rows,
                                                  s.order, s.quality.earlyTermination, w);
    });
    Image image = warp(f, w, camera.width(), camera.height(), edges,
                       float(s.quality.warpTolerance), s.quality.tileSize);
    stats.tilesMs = msSince(tiles);
    stats.sheetAxis = f.m;
    stats.sheetSign = sheetAxis(camera.view, scene.volume->spacing).sign;
    stats.sheets = std::size_t(sheets);
    for (const auto& [weights, hidden] : counts) {
        stats.footprintPixels += weights;
        stats.culledSplats += hidden;
    }
    return image;
}

}  // namespace splat
