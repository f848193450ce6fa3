// Stage-level tests of the frame pipeline (splat/src/frame, splatters, footprint lanes):
// each fast stage against a slow reference implementation of the same step, and the
// frame's threading contract.
#include <tbb/info.h>
#include <tbb/task_scheduler_observer.h>

#include <atomic>
#include <bit>
#include <catch2/catch.hpp>
#include <cstring>
#include <random>

#include "footprint/lanes.h"
#include "frame/chunk_binning.h"
#include "frame/compositing.h"
#include "frame/tile_binning.h"
#include "model/scene_impl.h"
#include "splat/error.h"
#include "splat/render.h"
#include "splat/scene.h"
#include "splat/synthetic.h"
#include "splatters/footprint_lanes.h"
#include "splatters/splatter.h"

using namespace splat;

TEST_CASE("binning: every tile lists exactly the splats whose rectangle touches it, in order",
          "[stages]") {
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> pos(-20, 140), size(0, 40);
    ProjectedSplats p;
    const std::size_t n = 3000;
    p.rect.resize(n);
    for (auto& r : p.rect) {
        const int x = pos(rng), y = pos(rng);
        r = {std::max(x, 0), std::max(y, 0), std::min(x + size(rng), 99),
             std::min(y + size(rng), 69)};
    }
    p.rect[5] = {1, 1, 0, 0};  // empty
    // Distinct per-splat values, so that a record copied from the wrong splat shows.
    std::vector<std::uint32_t> key(n), span(n);
    for (std::size_t q = 0; q < n; ++q) {
        p.sx.push_back(0.5f * float(q));
        p.sy.push_back(-0.25f * float(q));
        p.depth.push_back(3.0f + float(q));
        key[q] = std::uint32_t(q % 97);
        span[q] = std::uint32_t(1 + q % 5);
    }
    std::vector<std::uint32_t> order(n);
    for (std::size_t q = 0; q < n; ++q) order[q] = std::uint32_t((q * 7919) % n);
    const TileGrid grid(100, 70, 16);
    TileBins bins;
    binToTiles(p, order, key, span, grid, bins);
    REQUIRE(bins.begin.size() == std::size_t(grid.count()) + 1);
    for (int t = 0; t < grid.count(); ++t) {
        const int ox = (t % grid.tilesX) * 16, oy = (t / grid.tilesX) * 16;
        std::vector<std::uint32_t> expected;
        for (std::uint32_t id : order) {
            const PixelRect& r = p.rect[id];
            if (!r.empty() && r.x0 <= ox + 15 && r.x1 >= ox && r.y0 <= oy + 15 && r.y1 >= oy)
                expected.push_back(id);
        }
        std::vector<std::uint32_t> got;
        for (std::uint32_t q = bins.begin[t]; q < bins.begin[t + 1]; ++q) {
            const SheetRecord& rec = bins.records[q];
            got.push_back(rec.id);
            REQUIRE(rec.key == key[rec.id]);
            REQUIRE(rec.span == span[rec.id]);
            REQUIRE(rec.sx == p.sx[rec.id]);
            REQUIRE(rec.sy == p.sy[rec.id]);
            REQUIRE(rec.depth == p.depth[rec.id]);
        }
        REQUIRE(got == expected);
    }
}

TEST_CASE("chunk binning: runs in one sheet list every splat whose box touches a tile, in order",
          "[stages]") {
    // Splats of a 20^3 grid (a random third left out) in runs along rows (i, as the cells) and
    // along columns (j, as the slabs across i), from several directions. Expanding a tile's
    // entries and keeping the splats whose footprint box touches the tile (as the sweep does)
    // must give exactly the splats per-splat binning lists there, in visiting order, with the
    // screen positions of their own volume row.
    const Volume v = makeSynthetic("phantom", 20);
    const int n = 20;
    SplatList splats;
    splats.origin = v.origin;
    splats.spacing = v.spacing;
    std::mt19937 rng(3);
    std::vector<int> at(std::size_t(n * n * n), -1);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                if (rng() % 3 != 0) {
                    at[std::size_t((k * n + j) * n + i)] = int(splats.i.size());
                    splats.i.push_back(std::uint16_t(i));
                    splats.j.push_back(std::uint16_t(j));
                    splats.k.push_back(std::uint16_t(k));
                }
    // Runs along i (cells of 8) and along j (8 rows, one slice i at a time).
    std::vector<std::uint32_t> rowIds, rowRuns{0}, colIds, colRuns{0};
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i0 = 0; i0 < n; i0 += 8) {
                for (int i = i0; i < std::min(n, i0 + 8); ++i)
                    if (at[std::size_t((k * n + j) * n + i)] >= 0)
                        rowIds.push_back(std::uint32_t(at[std::size_t((k * n + j) * n + i)]));
                if (rowIds.size() != rowRuns.back()) rowRuns.push_back(std::uint32_t(rowIds.size()));
            }
    for (int k = 0; k < n; ++k)
        for (int j0 = 0; j0 < n; j0 += 8)
            for (int i = 0; i < n; ++i) {
                for (int j = j0; j < std::min(n, j0 + 8); ++j)
                    if (at[std::size_t((k * n + j) * n + i)] >= 0)
                        colIds.push_back(std::uint32_t(at[std::size_t((k * n + j) * n + i)]));
                if (colIds.size() != colRuns.back()) colRuns.push_back(std::uint32_t(colIds.size()));
            }
    const TileGrid grid(48, 40, 16);
    const std::vector<TileAccumulator> noTiles;
    const Occlusion occlusion(grid, noTiles, false);
    for (double az : {20.0, 70.0, 135.0}) {
        CameraParams params;
        params.width = 48;
        params.height = 40;
        params.azimuthDeg = az;
        params.elevationDeg = 15.0;
        const Camera camera(params, v);
        const SplatProjector projector(splats, camera, v.spacing, 2.0);
        // slice = j: the row runs are in one sheet each; slice = i: they cross sheets (one
        // entry per splat) and the column runs are in one sheet each.
        for (int pass = 0; pass < 3; ++pass) {
            const bool columns = pass == 2;
            const std::vector<std::uint32_t>& ids = columns ? colIds : rowIds;
            const std::vector<std::uint32_t>& runs = columns ? colRuns : rowRuns;
            const SplatRecordFields fields{pass == 0 ? splats.j.data() : splats.i.data(), nullptr};
            ChunkBins bins;
            const VisitOrder order{&ids, ids.size(), false};
            REQUIRE(binChunk(projector, order, runs, grid, occlusion, fields, bins) == 0);
            std::size_t pairs = 0, records = 0;
            for (int t = 0; t < grid.count(); ++t) {
                const int ox = (t % grid.tilesX) * 16, oy = (t / grid.tilesX) * 16;
                auto touches = [&](const PixelRect& r) {
                    return !r.empty() && r.x0 <= ox + 15 && r.x1 >= ox && r.y0 <= oy + 15 &&
                           r.y1 >= oy;
                };
                std::vector<std::uint32_t> expected, got;
                for (std::size_t q = 0; q < ids.size(); ++q) {
                    float sx, sy;
                    const std::uint32_t id = ids[q];
                    if (touches(projector.project(projector.row(id), id, sx, sy)))
                        expected.push_back(id);
                }
                for (std::uint32_t e = bins.begin[t]; e < bins.begin[t + 1]; ++e, ++records) {
                    const RunRecord& rec = bins.records[e];
                    for (std::uint32_t q = rec.local; q < rec.local + rec.count; ++q) {
                        const std::uint32_t id = ids[q];
                        REQUIRE(rec.slice == fields.slice[id]);
                        float sx, sy;
                        projector.project(projector.row(id), id, sx, sy);
                        REQUIRE(bins.sx[q] == sx);
                        REQUIRE(bins.sy[q] == sy);
                        if (touches(footprintRect(sx, sy, projector.shared(), grid.width,
                                                  grid.height)))
                            got.push_back(id);
                    }
                }
                REQUIRE(got == expected);
                pairs += expected.size();
            }
            INFO("azimuth " << az << " pass " << pass << ": " << records << " entries for "
                            << pairs << " splat-tile pairs");
            if (pass == 1)
                CHECK(records == pairs);  // runs across sheets: an entry per splat and tile
            else
                CHECK(records * 2 < pairs);  // runs in one sheet: one per run and tile
        }
    }
}

TEST_CASE("compositing: over (back to front) equals under (front to back) on random samples",
          "[stages]") {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const int pixels = 64, depth = 40;
    std::vector<Sample> samples(std::size_t(pixels) * depth);
    for (auto& s : samples) {
        const float a = u(rng) * u(rng);
        s = {a, a * u(rng), a * u(rng), a * u(rng)};  // premultiplied
    }
    TileAccumulator ftb(8, 8, CompositeOrder::FrontToBack, 0.0),
        btf(8, 8, CompositeOrder::BackToFront, 0.0);
    for (int d = 0; d < depth; ++d)
        for (int p = 0; p < pixels; ++p) {
            ftb.composite(p, samples[std::size_t(d) * pixels + p]);
            btf.composite(p, samples[std::size_t(depth - 1 - d) * pixels + p]);
        }
    Image a(8, 8), b(8, 8);
    ftb.resolve(a, 0, 0, RenderMode::Dvr);
    btf.resolve(b, 0, 0, RenderMode::Dvr);
    // The closed form: I = sum_d C_d prod_{e<d} (1 - a_e).
    for (int p = 0; p < pixels; ++p) {
        double t = 1, r = 0, alpha = 0;
        for (int d = 0; d < depth; ++d) {
            const Sample& s = samples[std::size_t(d) * pixels + p];
            r += t * s.r;
            alpha += t * s.alpha;
            t *= 1 - s.alpha;
        }
        REQUIRE(a.pixels[p].r == Approx(r).margin(1e-6));
        REQUIRE(b.pixels[p].r == Approx(r).margin(1e-6));
        REQUIRE(a.pixels[p].a == Approx(alpha).margin(1e-6));
        REQUIRE(b.pixels[p].a == Approx(alpha).margin(1e-6));
    }
    // Background after resolve: I + (1 - a) bg.
    Image c = a;
    applyBackground(c, RenderMode::Dvr, glm::vec4(0.2f, 0.3f, 0.4f, 1.0f), 0.0f);
    CHECK(c.pixels[0].g == Approx(a.pixels[0].g + (1 - a.pixels[0].a) * 0.3f).margin(1e-7));
    CHECK(c.pixels[0].a == Approx(1.0f).margin(1e-6));
}

TEST_CASE("compositing: a row of optical depths composites as sampleFromOpticalDepth does",
          "[stages]") {
    // The flush of pre-classified sheets composites whole rows (eight lanes with their own
    // exp where AVX2 is present); against the double-precision closed form per pixel, for
    // optical depths from 0 through the series/exp switch at 1/2 to 90 (exp underflows),
    // slightly negative ones (kernels with negative lobes), and row lengths 1..13 (tails).
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const float taus[] = {0.0f, 1e-9f, 1e-4f, 1e-3f, 0.01f, 0.3f,   0.49999f, 0.5f, 0.50001f,
                          0.9f, 2.0f,  7.5f,  30.0f, 90.0f, -1e-3f, -0.2f,    -0.6f};
    for (CompositeOrder order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront})
        for (int n = 1; n <= 13; ++n) {
            TileAccumulator acc(16, 2, order, 0.0);
            std::vector<float> tau(n), er(n), eg(n), eb(n);
            std::vector<double> R(n, 0.0), A(n, 0.0);
            for (int step = 0; step < 3; ++step) {
                for (int i = 0; i < n; ++i) {
                    tau[i] = taus[(i * 5 + step * 3 + n) % std::size(taus)];
                    er[i] = u(rng) * std::max(tau[i], 0.0f);
                    eg[i] = eb[i] = er[i];
                    const double t = tau[i], alpha = -std::expm1(-t);
                    const double c = t == 0 ? er[i] : er[i] * alpha / t;
                    if (order == CompositeOrder::FrontToBack) {
                        R[i] += (1 - A[i]) * c;
                        A[i] += (1 - A[i]) * alpha;
                    } else {
                        R[i] = c + (1 - alpha) * R[i];
                        A[i] = alpha + (1 - alpha) * A[i];
                    }
                }
                acc.compositeOpticalDepths(16 + 1, n, tau.data(), er.data(), eg.data(), eb.data());
            }
            Image img(16, 2);
            acc.resolve(img, 0, 0, RenderMode::Dvr);
            for (int i = 0; i < n; ++i) {
                INFO("n " << n << " pixel " << i);
                CHECK(img.at(1 + i, 1).r == Approx(R[i]).epsilon(2e-6).margin(1e-7));
                CHECK(img.at(1 + i, 1).a == Approx(A[i]).epsilon(2e-6).margin(1e-7));
            }
            // Pixels outside the row are untouched.
            CHECK(img.at(0, 1).a == 0.0f);
            if (1 + n < 16) CHECK(img.at(1 + n, 1).a == 0.0f);
            CHECK(img.at(1, 0).a == 0.0f);
        }
}

TEST_CASE("compositing: interleaved samples composite as the planes do, bit for bit, and clear",
          "[stages]") {
    // compositeInterleavedRowAndClear (the factorised sheets' rows: (tau, er, eg, eb) per
    // pixel) against compositeOpticalDepthRow on the same samples in planes: row lengths 1..21
    // (whole groups of eight and tails), groups of zero samples among others (passed over),
    // optical depths on both sides of the series/exp switch at 1/2.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (CompositeOrder order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront})
        for (int n = 1; n <= 21; ++n) {
            std::vector<float> planes[4], rows[2][4];
            for (auto& r : rows)
                for (auto& c : r) c.assign(std::size_t(n), 0.0f);
            for (int step = 0; step < 4; ++step) {
                std::vector<float> samples(4 * std::size_t(n), 0.0f);
                for (auto& c : planes) c.assign(std::size_t(n), 0.0f);
                for (int i = 0; i < n; ++i) {
                    if ((i / 8 + step) % 3 == 0) continue;  // a group (or part) of zeros
                    const float tau = u(rng) * (step % 2 ? 3.0f : 0.4f);
                    const float e[4] = {tau, u(rng) * tau, u(rng) * tau, u(rng) * tau};
                    for (int c = 0; c < 4; ++c) {
                        samples[4 * std::size_t(i) + std::size_t(c)] = e[c];
                        planes[c][std::size_t(i)] = e[c];
                    }
                }
                compositeOpticalDepthRow(rows[0][0].data(), rows[0][1].data(), rows[0][2].data(),
                                         rows[0][3].data(), order, n, planes[0].data(),
                                         planes[1].data(), planes[2].data(), planes[3].data());
                compositeInterleavedRowAndClear(rows[1][0].data(), rows[1][1].data(),
                                                rows[1][2].data(), rows[1][3].data(), order, n,
                                                samples.data());
                for (float x : samples) REQUIRE(std::bit_cast<std::uint32_t>(x) == 0u);
            }
            for (int c = 0; c < 4; ++c)
                for (int i = 0; i < n; ++i) {
                    INFO("n " << n << " channel " << c << " pixel " << i);
                    REQUIRE(std::bit_cast<std::uint32_t>(rows[1][c][std::size_t(i)]) ==
                            std::bit_cast<std::uint32_t>(rows[0][c][std::size_t(i)]));
                }
            CHECK(rows[0][3][0] > 0.0f);
        }
}

#if defined(FOOTPRINT_HAVE_LANES)
namespace {
struct LaneErrors {
    double table = 0, poly = 0, fraction = 0;
};
// Largest differences between the lanes and the scalar lookups over r^2 in [0, R^2) and
// z in [-2.5, 2.5] (compiled for AVX2 + FMA like the splatters' loops).
FOOTPRINT_LANES_BEGIN
LaneErrors laneErrors(const footprint::FootprintTable& table, const footprint::FootprintPoly& poly,
                      const footprint::SlabTable& slabs) {
    const footprint::FootprintLanes fromTable(table, nullptr), fromPoly(table, &poly);
    const footprint::FractionLanes fraction(slabs);
    const float r2max = table.r2Max();
    LaneErrors worst;
    alignas(32) float r2[8], z[8], out[8];
    for (int n = 0; n < 4096; n += 8) {
        for (int l = 0; l < 8; ++l) {
            r2[l] = r2max * float(n + l) / 4100.0f;
            z[l] = -2.5f + 5.0f * float((n + l) * 37 % 4096) / 4096.0f;
        }
        const __m256 v = _mm256_load_ps(r2);
        _mm256_store_ps(out, fromTable(v));
        for (int l = 0; l < 8; ++l)
            worst.table = std::max(worst.table, double(std::abs(out[l] - table.lookup(r2[l]))));
        _mm256_store_ps(out, fromPoly(v));
        for (int l = 0; l < 8; ++l)
            worst.poly = std::max(worst.poly, double(std::abs(out[l] - table.lookup(r2[l]))));
        _mm256_store_ps(out, fraction(fraction.radial(v), _mm256_load_ps(z)));
        for (int l = 0; l < 8; ++l)
            worst.fraction =
                std::max(worst.fraction, double(std::abs(out[l] - slabs.fraction(r2[l], z[l]))));
    }
    return worst;
}
FOOTPRINT_LANES_END

/// True when this CPU runs the lanes (else a warning: the scalar lookups are used everywhere).
bool lanesOnThisCpu() {
    if (footprint::cpuHasLanes()) return true;
    WARN("this CPU has no AVX2 + FMA: the scalar lookups are used everywhere");
    return false;
}

/// The default Gaussian kernel's footprint table and polynomial.
struct DefaultFootprint {
    footprint::Kernel kernel = footprint::Kernel::fromName("gaussian", 0, 0);
    footprint::FootprintTable table{kernel};
    footprint::FootprintPoly poly{table};
};
}  // namespace

TEST_CASE("footprint lanes equal the tables' scalar lookups", "[stages]") {
    if (!lanesOnThisCpu()) return;
    const DefaultFootprint f;
    const footprint::FootprintTable& table = f.table;
    const footprint::SlabTable slabs(f.kernel);
    const LaneErrors worst = laneErrors(table, f.poly, slabs);
    const double peak = table.peak();
    CHECK(worst.table <= 1e-7 * peak);   // the same interpolation, FMA rounding only
    CHECK(worst.poly <= 1.5e-6 * peak);  // FootprintPoly's tolerance, 1e-6 of the peak
    CHECK(worst.fraction <= 1e-6);       // F in [0, 1], the same bilinear interpolation
}

TEST_CASE("footprint lanes: two rows per group fill the sheet of one row per group, bit for bit",
          "[stages][axis]") {
    if (!lanesOnThisCpu()) return;
    const DefaultFootprint f;
    const footprint::Kernel& kernel = f.kernel;
    const footprint::FootprintTable& table = f.table;
    const footprint::FootprintPoly& poly = f.poly;
    REQUIRE(Degree5Lanes::fits(poly));
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0), pixel(0.4, 2.5);
    std::uniform_real_distribution<float> pos(-3.0f, 35.0f), val(0.0f, 2.0f);
    // A tile at (32, 64) of a 96 x 128 image; oblique views and pixels of 0.4 to 2.5 voxels
    // give boxes 2 to 12 pixels wide.
    const int ox = 32, oy = 64, width = 96, height = 128;
    int narrow = 0, wide = 0;
    for (int view = 0; view < 20; ++view) {
        const glm::dvec3 dir = glm::normalize(glm::dvec3(u(rng), u(rng), 1.5 + u(rng)));
        const glm::dvec3 right = glm::normalize(glm::cross(dir, glm::dvec3(0.3, 1.0, 0.1)));
        const glm::dvec3 up = glm::cross(right, dir);
        const double size = pixel(rng);
        const footprint::EllipticalFootprint e = footprint::ellipticalFootprint(
            glm::dvec3(1.0, 1.0, 1.5), right * size, -up * size, dir, kernel.radius());
        SheetBuffer<4> paired(ox, oy, 32, 32), single(ox, oy, 32, 32);
        for (int n = 0; n < 60; ++n) {
            const float sx = float(ox) + pos(rng), sy = float(oy) + pos(rng);
            const PixelRect r = clipToTile(footprintRect(sx, sy, e, width, height),
                                           TileGrid(width, height, 32), ox, oy);
            if (r.empty()) continue;
            (r.x1 - r.x0 < 4 ? narrow : wide) += 1;
            const float v[4] = {val(rng), val(rng), val(rng), val(rng)};
            const Degree5Lanes fp(poly);
            const int a = splatFootprintLanes(paired, v, sx, sy, e, r, table, fp, true);
            const int b = splatFootprintLanes(single, v, sx, sy, e, r, table, fp, false);
            REQUIRE(a == b);
        }
        for (int c = 0; c < 4; ++c)
            for (int y = 0; y < 32; ++y)
                REQUIRE(std::memcmp(paired.row(c, y), single.row(c, y), 32 * sizeof(float)) == 0);
    }
    INFO(narrow << " narrow and " << wide << " wide boxes");
    CHECK(narrow > 100);
    CHECK(wide > 100);
}
#endif

namespace {
// Counts worker threads that join the calling thread's implicit arena.
class WorkerCounter : public tbb::task_scheduler_observer {
  public:
    WorkerCounter() { observe(true); }
    ~WorkerCounter() override { observe(false); }
    void on_scheduler_entry(bool isWorker) override {
        if (isWorker) ++entries;
    }
    std::atomic<int> entries{0};
};
}  // namespace

TEST_CASE("threads = 1 runs every stage of a frame (and classification) on one thread",
          "[stages]") {
    const Volume v = makeSynthetic("phantom", 48);
    RenderSettings s;
    s.transfer = TransferFunction::preset("ct-soft");
    s.camera.width = s.camera.height = 96;
    s.camera.azimuthDeg = 30;
    s.shading.enabled = true;
    // Every one-thread frame first: TBB workers of an all-cores frame linger in the arena for
    // a moment after it ends, and an observer made then counts them (a flake under load).
    const RendererKind kinds[] = {RendererKind::Axis, RendererKind::Sheet, RendererKind::Reference};
    std::vector<Image> single;
    for (RendererKind k : kinds) {
        s.renderer = k;
        s.threads = 1;
        WorkerCounter one;
        single.push_back(render(v, s));
        CHECK(one.entries == 0);
    }
    if (tbb::info::default_concurrency() < 2) return;
    for (std::size_t i = 0; i < single.size(); ++i) {
        s.renderer = kinds[i];
        s.threads = 0;  // all cores: workers join the caller's arena (the check is alive)
        WorkerCounter all;
        const Image b = render(v, s);
        CHECK(all.entries > 0);
        REQUIRE(single[i].pixels == b.pixels);  // and the image does not depend on it
    }
}

TEST_CASE("one Scene renders every renderer; frames report their sheet orientation", "[stages]") {
    const Volume v = makeSynthetic("phantom", 48);
    RenderSettings s;
    s.transfer = TransferFunction::preset("ct-soft");
    s.camera.width = s.camera.height = 64;
    const Scene scene(v, s);
    CameraParams cam = s.camera;
    for (double az : {10.0, 44.0, 46.0, 100.0, 170.0, 260.0}) {
        cam.azimuthDeg = az;
        RenderStats st;
        const Image axis = scene.render(RendererKind::Axis, cam, &st);
        // Azimuth a looks along (-sin a, cos a, 0): the sheets follow the larger component.
        const double sx = -std::sin(az * 3.14159265358979 / 180),
                     sy = std::cos(az * 3.14159265358979 / 180);
        const int axisExpected = std::abs(sx) >= std::abs(sy) ? 0 : 1;
        CHECK(st.sheetAxis == axisExpected);
        CHECK(st.sheetSign == ((axisExpected == 0 ? sx : sy) >= 0 ? 1 : -1));
        const Image sheet = scene.render(RendererKind::Sheet, cam, &st);
        CHECK(st.sheetAxis == -1);
        CHECK(st.slabs > 0);
        // The same frame through a fresh Renderer is the same image.
        RenderSettings one = s;
        one.camera = cam;
        one.renderer = RendererKind::Axis;
        REQUIRE(render(v, one).pixels == axis.pixels);
        one.renderer = RendererKind::Sheet;
        REQUIRE(render(v, one).pixels == sheet.pixels);
    }
    // A frame cannot change what the Scene classified.
    RenderSettings post = s;
    post.classification = Classification::Post;
    CHECK_THROWS_AS(scene.render(post), Error);
}

TEST_CASE("anisotropic spacing: the sheet axis is the major axis of S^-1 view", "[stages]") {
    // Spacing 1 x 1 x 4: looking down at 30 degrees elevation the world view is mostly
    // horizontal, but in index space the z component is 4x smaller still.
    CHECK(
        sheetAxis(glm::dvec3(0.0, std::cos(0.5236), -std::sin(0.5236)), glm::dvec3(1, 1, 4)).axis ==
        1);
    // Spacing 4 x 1 x 1 at azimuth 60: world view mostly along -x, index space along y.
    CHECK(
        sheetAxis(glm::dvec3(-std::sin(1.0472), std::cos(1.0472), 0.0), glm::dvec3(4, 1, 1)).axis ==
        1);
    CHECK(
        sheetAxis(glm::dvec3(-std::sin(1.0472), std::cos(1.0472), 0.0), glm::dvec3(1, 1, 1)).axis ==
        0);
    CHECK(sheetAxis(glm::dvec3(0, 0, -1), glm::dvec3(1, 1, 1)).sign == -1);
}
