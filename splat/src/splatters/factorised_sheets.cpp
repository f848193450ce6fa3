// Factorised sheets (see factorised_sheets.h): stamps, bands of the intermediate image,
// the warp.
#include "splatters/factorised_sheets.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>

#include "footprint/ellipse.h"
#include "footprint/lanes.h"
#include "frame/compositing.h"
#include "frame/stopwatch.h"
#include "splatters/cell_index.h"
#include "splatters/splatter.h"

namespace splat {

namespace {

constexpr int kBand = 16;  ///< intermediate rows per band: the unit of parallel work
constexpr int kBlock = 8;  ///< early termination: a band's opacity is tested per 8 columns

/// The view's factorisation: sheets along axis m (sheet q, voxel (u, v) on the screen at
/// c + J (u + shear.x q, v + shear.y q)) and the intermediate grid, sample (a, b) at sheet
/// coordinates (U0 + a / n, V0 + b / n), of which the window [a0, a0 + width) x [b0, b0 +
/// height) covers the screen.
struct Factorisation {
    int m, u, v;
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
    f.n = std::max(1, s.quality.factorisedSheets);
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
/// stamp (stampH rows of stampW weights, zero outside the footprint).
struct SheetStamp {
    int a, b;
    std::vector<float> w;
};

SheetStamp sheetStamp(const Factorisation& f, int q, const footprint::FootprintTable& table) {
    const double sU = (f.shear.x * q - f.U0) * f.n, sV = (f.shear.y * q - f.V0) * f.n;
    SheetStamp st;
    st.a = int(std::floor(sU));
    st.b = int(std::floor(sV));
    const double phaseU = sU - st.a, phaseV = sV - st.b;
    st.w.assign(std::size_t(f.stampW) * f.stampH, 0.0f);
    for (int y = 0; y < f.stampH; ++y)
        for (int x = 0; x < f.stampW; ++x) {
            // The sample's offset from the voxel centre, sheet units, then screen pixels.
            const double dU = (f.dA + x - phaseU) / f.n, dV = (f.dB + y - phaseV) / f.n;
            const glm::dvec2 p = f.colU * dU + f.colV * dV;
            const float r2 = f.e.r2(float(p.x), float(p.y));
            if (r2 < f.r2Max) st.w[std::size_t(y) * f.stampW + x] = table.lookup(r2) * f.e.scale;
        }
    return st;
}

/// The factorised sheets' state per scene (Scene::Impl::state), made on first use: the
/// list's order along i (a counting sort on the slice index; the list is in (k, j, i) order,
/// so sorting by i keeps rows by (k, j) within a slice) and where each slice starts in it.
class SliceOrderI {
  public:
    explicit SliceOrderI(const Scene::Impl& scene) : scene_(scene) {}
    struct Order {
        std::vector<std::uint32_t> order, start;
        std::uint32_t at(std::size_t n) const { return order[n]; }
    };
    const Order& get() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!order_) {
            const std::vector<std::uint16_t>& index = scene_.splats.i;
            auto o = std::make_unique<Order>();
            o->start.assign(std::size_t(scene_.volume->dims.x) + 1, 0);
            for (std::uint16_t q : index) ++o->start[std::size_t(q) + 1];
            for (std::size_t q = 1; q < o->start.size(); ++q) o->start[q] += o->start[q - 1];
            std::vector<std::uint32_t> next(o->start.begin(), o->start.end() - 1);
            o->order.resize(index.size());
            for (std::size_t n = 0; n < index.size(); ++n) o->order[next[index[n]]++] = std::uint32_t(n);
            order_ = std::move(o);
        }
        return *order_;
    }

  private:
    const Scene::Impl& scene_;
    std::mutex mutex_;
    std::unique_ptr<Order> order_;
};

/// The splats in sheet order: sheet q holds [start[q], start[q + 1]), by row v then u.
struct SheetSplats {
    std::vector<std::uint16_t> u, v;
    std::vector<glm::vec4> value;  ///< (rho, e_r, e_g, e_b)
    const std::vector<std::uint32_t>* start;
};

SheetSplats sheetSplats(const Scene::Impl& scene, int m, int u, int v, const float* er,
                        const float* eg, const float* eb) {
    const SplatList& s = scene.splats;
    (void)m;  // sheets along i only: the other axes read the list in place (ListRows)
    const SliceOrderI::Order& order = scene.state<SliceOrderI>().get();
    const std::vector<std::uint16_t>* axes[3] = {&s.i, &s.j, &s.k};
    const std::vector<std::uint16_t>&iu = *axes[u], &iv = *axes[v];
    SheetSplats out;
    out.start = &order.start;
    const std::size_t n = s.size();
    out.u.resize(n);
    out.v.resize(n);
    out.value.resize(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t p = r.begin(); p != r.end(); ++p) {
                              const std::uint32_t id = order.at(p);
                              out.u[p] = iu[id];
                              out.v[p] = iv[id];
                              glm::vec4 e = s.emission(id);
                              if (er) e = glm::vec4(e.x, er[id], eg[id], eb[id]);
                              out.value[p] = e;
                          }
                      });
    return out;
}

/// The splats of row v of sheet q, list positions [first, second), by u, from one of two
/// sources. Sheets along j or k (ListRows): a row (k, j) of the list is consecutive
/// (CellIndex::cellStarts), read in place. Sheets along i (GatheredRows): the list
/// gathered in sheet order (SheetSplats), rows found by bisection.
struct ListRows {
    const SplatList& s;
    const std::vector<std::uint32_t>& cells;
    std::size_t ny, cx;
    int m, rows;  ///< sheet axis (1 or 2), rows per sheet
    const float *er, *eg, *eb;
    std::pair<std::size_t, std::size_t> range(int q, int v) const {
        const std::size_t k = std::size_t(m == 2 ? q : v), j = std::size_t(m == 2 ? v : q);
        const std::size_t c = (k * ny + j) * cx;
        return {cells[c], cells[c + cx]};
    }
    int u(std::size_t p) const { return s.i[p]; }
    glm::vec4 value(std::size_t p) const {
        const glm::vec4 e = s.emission(p);
        return er ? glm::vec4(e.x, er[p], eg[p], eb[p]) : e;
    }
};

struct GatheredRows {
    const SheetSplats& list;
    int rows;
    std::pair<std::size_t, std::size_t> range(int q, int v) const {
        const std::vector<std::uint32_t>& start = *list.start;
        const auto first = list.v.begin() + std::ptrdiff_t(start[std::size_t(q)]),
                   last = list.v.begin() + std::ptrdiff_t(start[std::size_t(q) + 1]);
        const auto lo = std::lower_bound(first, last, std::uint16_t(v));
        const auto hi = std::upper_bound(lo, last, std::uint16_t(v));
        return {std::size_t(lo - list.v.begin()), std::size_t(hi - list.v.begin())};
    }
    int u(std::size_t p) const { return list.u[p]; }
    const glm::vec4& value(std::size_t p) const { return list.value[p]; }
};

/// The composited intermediate window: premultiplied colour and opacity, row-major.
struct Composited {
    std::vector<float> r, g, b, a;
};

#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
/// Adds value * stamp row to the four planes at `p` (planes `plane` floats apart), eight
/// weights at a time; `width` is a multiple of 8.
inline void addStampRowLanes(float* p, std::size_t plane, const float* w, int width,
                             const glm::vec4& value) {
    const __m256 v0 = _mm256_set1_ps(value.x), v1 = _mm256_set1_ps(value.y),
                 v2 = _mm256_set1_ps(value.z), v3 = _mm256_set1_ps(value.w);
    float *p1 = p + plane, *p2 = p1 + plane, *p3 = p2 + plane;
    for (int x = 0; x < width; x += 8) {
        const __m256 wv = _mm256_loadu_ps(w + x);
        _mm256_storeu_ps(p + x, _mm256_fmadd_ps(v0, wv, _mm256_loadu_ps(p + x)));
        _mm256_storeu_ps(p1 + x, _mm256_fmadd_ps(v1, wv, _mm256_loadu_ps(p1 + x)));
        _mm256_storeu_ps(p2 + x, _mm256_fmadd_ps(v2, wv, _mm256_loadu_ps(p2 + x)));
        _mm256_storeu_ps(p3 + x, _mm256_fmadd_ps(v3, wv, _mm256_loadu_ps(p3 + x)));
    }
}
FOOTPRINT_LANES_END
#endif

inline void addStampRow(float* p, std::size_t plane, const float* w, int width,
                        const glm::vec4& value) {
#if defined(FOOTPRINT_HAVE_LANES)
    if (footprint::cpuHasLanes()) {
        addStampRowLanes(p, plane, w, width, value);
        return;
    }
#endif
    for (int c = 0; c < 4; ++c, p += plane)
        for (int x = 0; x < width; ++x) p[x] += value[c] * w[x];
}

/// One band of the window, rows [row0, row0 + rows): every sheet in visiting order, its
/// splats' stamps added into the band's sheet buffer (tau, E_r, E_g, E_b planes with the
/// stamp's width of margin either side), then composited into `out`. Front to back, a
/// splat whose columns are opaque (every pixel of the band in each 8-column block) is
/// skipped, and the band ends when all are. Returns the weights added.
template <class Rows>
std::size_t renderBand(const Factorisation& f, const Rows& list, int sheets,
                       const std::vector<SheetStamp>& stamps, int row0, int rows,
                       CompositeOrder order, double earlyTermination, Composited& out) {
    const int margin = f.stampW, stride = f.width + 2 * f.stampW + 8;
    const std::size_t plane = std::size_t(stride) * rows;
    std::vector<float> sheet(4 * plane, 0.0f);
    const bool terminates = order == CompositeOrder::FrontToBack && earlyTermination > 0;
    const float threshold = float(1.0 - earlyTermination);
    const int blocks = (f.width + kBlock - 1) / kBlock;
    std::vector<std::uint8_t> opaque(std::size_t(blocks), 0);
    int opaqueCount = 0;
    std::size_t weights = 0;
    const int n = f.n;
    auto floorDiv = [](int x, int y) { return x >= 0 ? x / y : -((-x + y - 1) / y); };
    for (int k = 0; k < sheets && !(terminates && opaqueCount == blocks); ++k) {
        const int q = f.ascending ? k : sheets - 1 - k;
        const SheetStamp& st = stamps[std::size_t(q)];
        // Voxel rows whose stamp rows n v + st.b + dB - b0 + [0, stampH) meet the band.
        const int top = st.b + f.dB - f.b0;
        const int vLo = std::max(0, -floorDiv(top + f.stampH - 1 - row0, n));
        const int vHi = std::min(floorDiv(row0 + rows - 1 - top, n), list.rows - 1);
        int x0 = stride, x1 = -1, y0 = rows, y1 = -1;
        for (int v = vLo; v <= vHi; ++v) {
            const auto [pFirst, pEnd] = list.range(q, v);
            const int row = n * v + top - row0;  // stamp row 0, band rows
            const int ys = std::max(0, -row), ye = std::min(f.stampH, rows - row);
            for (std::size_t p = pFirst; p < pEnd; ++p) {
                const int col = n * list.u(p) + st.a + f.dA - f.a0;  // stamp column 0
                if (col + f.stampW <= 0 || col >= f.width) continue;
                if (terminates) {
                    const int c0 = std::max(col, 0) / kBlock,
                              c1 = std::min(col + f.stampW - 1, f.width - 1) / kBlock;
                    bool hidden = true;
                    for (int c = c0; c <= c1 && hidden; ++c) hidden = opaque[std::size_t(c)] != 0;
                    if (hidden) continue;
                }
                const glm::vec4 value = list.value(p);
                for (int y = ys; y < ye; ++y)
                    addStampRow(&sheet[std::size_t(row + y) * stride + std::size_t(col + margin)],
                                plane, &st.w[std::size_t(y) * f.stampW], f.stampW, value);
                weights += std::size_t(ye - ys) * std::size_t(f.stampW);
                x0 = std::min(x0, col);
                x1 = std::max(x1, col + f.stampW - 1);
                y0 = std::min(y0, row + ys);
                y1 = std::max(y1, row + ye - 1);
            }
        }
        if (x1 < x0) continue;
        // Composite the written rectangle (its part inside the window), then clear it.
        const int c0 = std::max(x0, 0), c1 = std::min(x1, f.width - 1);
        for (int y = y0; y <= y1; ++y) {
            float* t = &sheet[std::size_t(y) * stride];
            if (c1 >= c0) {
                const std::size_t o = std::size_t(row0 + y) * f.width + std::size_t(c0);
                compositeOpticalDepthRow(&out.r[o], &out.g[o], &out.b[o], &out.a[o], order,
                                         c1 - c0 + 1, t + margin + c0, t + plane + margin + c0,
                                         t + 2 * plane + margin + c0, t + 3 * plane + margin + c0);
            }
            for (int c = 0; c < 4; ++c)
                std::fill(t + c * plane + margin + x0, t + c * plane + margin + x1 + 1, 0.0f);
        }
        if (!terminates || c1 < c0) continue;
        for (int b = c0 / kBlock; b <= c1 / kBlock; ++b) {
            if (opaque[std::size_t(b)]) continue;
            bool all = true;
            const int xe = std::min(f.width, (b + 1) * kBlock);
            for (int y = 0; y < rows && all; ++y)
                for (int x = b * kBlock; x < xe; ++x)
                    if (out.a[std::size_t(row0 + y) * f.width + std::size_t(x)] < threshold) {
                        all = false;
                        break;
                    }
            if (all) {
                opaque[std::size_t(b)] = 1;
                ++opaqueCount;
            }
        }
    }
    return weights;
}

/// Catmull-Rom weights of the four samples around a point t in [0, 1) past the second.
inline void catmullRom(float t, float (&w)[4]) {
    w[0] = ((-t + 2.0f) * t - 1.0f) * t * 0.5f;
    w[1] = ((3.0f * t - 5.0f) * t * t + 2.0f) * 0.5f;
    w[2] = ((-3.0f * t + 4.0f) * t + 1.0f) * t * 0.5f;
    w[3] = (t - 1.0f) * t * t * 0.5f;
}

/// The screen image: the composited window at each pixel centre, by the Catmull-Rom spline
/// through its samples, opacity clamped to [0, 1] and colour to [0, opacity] (the spline's
/// overshoot at opaque edges).
Image warp(const Factorisation& f, const Composited& w, int width, int height) {
    Image image(width, height);
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const glm::dvec2 p = f.sheet({x + 0.5, y + 0.5});
            const double ga = (p.x - f.U0) * f.n - f.a0, gb = (p.y - f.V0) * f.n - f.b0;
            const double fa = std::floor(ga), fb = std::floor(gb);
            if (!(fa >= 1 && fb >= 1 && fa + 2 < f.width && fb + 2 < f.height)) continue;
            const float ta = float(ga - fa), tb = float(gb - fb);
            float wa[4], wb[4];
            catmullRom(ta, wa);
            catmullRom(tb, wb);
            const std::size_t o =
                (std::size_t(fb) - 1) * std::size_t(f.width) + std::size_t(fa) - 1;
            glm::vec4 sum(0.0f);
            for (int j = 0; j < 4; ++j) {
                const std::size_t r = o + std::size_t(j) * std::size_t(f.width);
                glm::vec4 row(0.0f);
                for (int i = 0; i < 4; ++i)
                    row += wa[i] * glm::vec4(w.r[r + i], w.g[r + i], w.b[r + i], w.a[r + i]);
                sum += wb[j] * row;
            }
            const float a = std::clamp(sum.a, 0.0f, 1.0f);
            image.at(x, y) = glm::vec4(std::clamp(sum.r, 0.0f, a), std::clamp(sum.g, 0.0f, a),
                                       std::clamp(sum.b, 0.0f, a), a);
        }
    });
    return image;
}

}  // namespace

bool factorisedSheetsApply(const Camera& camera, const RenderSettings& s, bool labels, bool clipped,
                           double lowPass, int level) {
    return s.quality.factorisedSheets > 0 && s.renderer == RendererKind::Axis &&
           !camera.perspective() && s.mode == RenderMode::Dvr &&
           s.classification == Classification::Pre && !labels && !clipped && !(lowPass > 0) &&
           level == 0;
}

Image renderFactorisedSheets(const Scene::Impl& scene, const Camera& camera,
                             const RenderSettings& s, const float* er, const float* eg,
                             const float* eb, RenderStats& stats) {
    const auto start = Clock::now();
    const Factorisation f = factorise(scene, camera, s);
    const glm::ivec3 dims = scene.volume->dims;
    const int sheets = dims[f.m];
    // Sheets along i cross the list's rows: gathered in sheet order; others read in place.
    SheetSplats gathered;
    if (f.m == 0) gathered = sheetSplats(scene, f.m, f.u, f.v, er, eg, eb);
    const GatheredRows gatheredRows{gathered, dims[f.v]};
    CellIndex& cells = scene.state<CellIndex>();
    const ListRows listRows{scene.splats,
                            cells.cellStarts(),
                            std::size_t(dims.y),
                            std::size_t(cells.cellsX()),
                            f.m,
                            dims[f.v],
                            er,
                            eg,
                            eb};
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
    std::vector<std::size_t> weights(std::size_t(bands), 0);
    tbb::parallel_for(0, bands, [&](int k) {
        const int row0 = k * kBand, rows = std::min(kBand, f.height - row0);
        weights[std::size_t(k)] = f.m == 0 ? renderBand(f, gatheredRows, sheets, stamps, row0, rows,
                                                        s.order, s.quality.earlyTermination, w)
                                           : renderBand(f, listRows, sheets, stamps, row0, rows,
                                                        s.order, s.quality.earlyTermination, w);
    });
    Image image = warp(f, w, camera.width(), camera.height());
    stats.tilesMs = msSince(tiles);
    stats.sheetAxis = f.m;
    stats.sheetSign = sheetAxis(camera.view, scene.volume->spacing).sign;
    stats.sheets = std::size_t(sheets);
    for (std::size_t n : weights) stats.footprintPixels += n;
    return image;
}

}  // namespace splat
