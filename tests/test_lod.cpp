// Level of detail (Quality::lod, splat/src/model/level_of_detail.h): the 2x level
// of a scene against brute-force cell averages, closed forms of X-ray and dvr through a
// constant box with bounds derived from the footprint's lattice ripple, the box-filtered
// volume it stands for, when a level is used, and the command line.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

#include "cli_util.h"
#include "footprint/footprint_table.h"
#include "footprint/kernel.h"
#include "model/level_of_detail.h"
#include "model/scene_impl.h"
#include "splat/error.h"
#include "splat/metrics.h"
#include "splat/render.h"
#include "splat/scene.h"
#include "splat/synthetic.h"

using namespace splat;
using splat::test::readTextFile;
using splat::test::RunResult;
using splat::test::runSplat;
using splat::test::testTmpDir;

namespace {

/// The transfer function of the timing runs in docs/speed-vs-accuracy.md "Level of detail".
TransferFunction timingTransfer() {
    TransferFunction tf;
    tf.normalized = true;
    tf.points = {{0.0f, {0, 0, 0, 0}},
                 {0.25f, {0.45f, 0.3f, 0.25f, 0.0f}},
                 {0.5f, {0.9f, 0.6f, 0.5f, 0.3f}},
                 {1.0f, {1, 1, 1, 0.8f}}};
    return tf;
}

/// Pre-classified dvr with the timing transfer function on 2 threads, size^2 pixels.
RenderSettings timingView(int size, double azimuth, double elevation) {
    RenderSettings s;
    s.transfer = timingTransfer();
    s.threads = 2;
    s.camera.width = s.camera.height = size;
    s.camera.azimuthDeg = azimuth;
    s.camera.elevationDeg = elevation;
    return s;
}

/// Largest relative ripple of the footprint summed over a square lattice of `step` voxels,
/// max over the lattice's offsets u of |sum_p fp(|u - p|^2) step^2 - 1|: an axis-aligned
/// X-ray pixel inside a constant region sums the columns' footprints on the unit lattice
/// (step 1), and one splat's footprint summed over the pixels of an image of pixel size
/// `step` voxels weighs step^2 times this sum.
double latticeRipple(const footprint::FootprintTable& table, double step) {
    const double R = table.radius();
    const int reach = int(std::ceil(R / step)) + 1;
    double worst = 0;
    constexpr int kOffsets = 48;  // fp is smooth: its ripple is resolved at 1/48 of a step
    for (int a = 0; a <= kOffsets; ++a)
        for (int b = 0; b <= a; ++b) {  // symmetric in u_x, u_y
            const double ux = step * a / kOffsets, uy = step * b / kOffsets;
            double sum = 0;
            for (int p = -reach; p <= reach; ++p)
                for (int q = -reach; q <= reach; ++q) {
                    const double dx = ux - p * step, dy = uy - q * step;
                    sum += table.lookup(float(dx * dx + dy * dy));
                }
            worst = std::max(worst, std::abs(sum * step * step - 1.0));
        }
    return worst;
}

/// A cube of value `c` over indices [lo, hi) on every axis of an n^3 volume of spacing 1.
Volume boxVolume(int n, int lo, int hi, float c) {
    Volume v = makeVolume({n, n, n}, {1.0, 1.0, 1.0}, "box");
    for (int k = lo; k < hi; ++k)
        for (int j = lo; j < hi; ++j)
            for (int i = lo; i < hi; ++i) v.at(i, j, k) = c;
    return v;
}

}  // namespace

TEST_CASE("lod: the 2x level of a 5x3x7 volume averages each cell, odd edges included", "[lod]") {
    // Anisotropic spacing and an offset origin; about a third of the voxels classified away.
    Volume v = makeVolume({5, 3, 7}, {0.5, 1.0, 2.0}, "odd");
    v.origin = {10.0, -3.0, 7.0};
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (float& d : v.data) d = u(rng);
    RenderSettings s;
    s.transfer = timingTransfer();  // alpha 0 up to 0.25: those voxels are no splats
    s.shading.enabled = true;       // unit normals per splat
    const Scene scene(v, s);
    const Scene::Impl& fine = scene.impl();
    REQUIRE(fine.splats.size() < v.voxelCount());
    REQUIRE(fine.splats.size() > v.voxelCount() / 2);
    const Scene::Impl* coarse = fine.coarser();
    REQUIRE(coarse != nullptr);
    CHECK(coarse->level == 1);
    CHECK(coarse->volume->dims == glm::ivec3(3, 2, 4));
    CHECK(coarse->volume->spacing == glm::dvec3(1.0, 2.0, 4.0));
    CHECK(coarse->volume->origin == glm::dvec3(10.25, -2.5, 8.0));

    // Brute force from the volume: every cell with at least one splat, in (k, j, i) order.
    const TransferFunction& tf = scene.settings().transfer;
    const SplatList& c = coarse->splats;
    std::size_t n = 0;
    for (int K = 0; K < 4; ++K)
        for (int J = 0; J < 2; ++J)
            for (int I = 0; I < 3; ++I) {
                int members = 0;
                double d = 0;
                glm::dvec4 e(0.0);
                for (int k = 2 * K; k < std::min(2 * K + 2, 7); ++k)
                    for (int j = 2 * J; j < std::min(2 * J + 2, 3); ++j)
                        for (int i = 2 * I; i < std::min(2 * I + 2, 5); ++i) {
                            const float value = v.at(i, j, k);
                            const glm::vec4 rgba = tf.sample(value);
                            const double rho = tf.extinctionFromOpacity(rgba.a);
                            if (!(rho > 0)) continue;
                            ++members;
                            d += value;
                            e += glm::dvec4(rho, rgba.r * rho, rgba.g * rho, rgba.b * rho);
                        }
                if (members == 0) continue;
                INFO("cell " << I << "," << J << "," << K);
                REQUIRE(n < c.size());
                CHECK(c.i[n] == I);
                CHECK(c.j[n] == J);
                CHECK(c.k[n] == K);
                // The merged splat sits at the cell centre of the fine grid.
                const glm::dvec3 centre =
                    v.world(glm::dvec3(2 * I + 0.5, 2 * J + 0.5, 2 * K + 0.5));
                CHECK(glm::length(c.world(n) - centre) < 1e-12);
                CHECK(c.density[n] == Approx(d / 8).epsilon(1e-6));
                const glm::vec4 got = c.emission(n);
                for (int q = 0; q < 4; ++q) CHECK(got[q] == Approx(e[q] / 8).epsilon(1e-6));
                const double len = glm::length(glm::dvec3(c.nx[n], c.ny[n], c.nz[n]));
                CHECK((std::abs(len - 1.0) < 1e-5 || len == 0.0));
                ++n;
            }
    CHECK(n == c.size());
    // Cells on the odd faces (I = 2, J = 1, K = 3) hold fewer voxels: the average over
    // eight keeps the integral of rho over the volume (kernel integral: one voxel volume).
    double fineMass = 0, coarseMass = 0;
    for (std::size_t q = 0; q < fine.splats.size(); ++q) fineMass += fine.splats.emission(q).x;
    for (std::size_t q = 0; q < c.size(); ++q) coarseMass += c.emission(q).x;
    const double fineVoxel = 0.5 * 1.0 * 2.0, coarseVoxel = 8 * fineVoxel;
    CHECK(coarseMass * coarseVoxel == Approx(fineMass * fineVoxel).epsilon(1e-6));

    // The next levels: (2, 1, 2), then (1, 1, 1), the last.
    const Scene::Impl* l2 = coarse->coarser();
    REQUIRE(l2 != nullptr);
    CHECK(l2->volume->dims == glm::ivec3(2, 1, 2));
    const Scene::Impl* l3 = l2->coarser();
    REQUIRE(l3 != nullptr);
    CHECK(l3->volume->dims == glm::ivec3(1, 1, 1));
    CHECK(l3->splats.size() == 1);
    CHECK(l3->coarser() == nullptr);
    double topMass = l3->splats.emission(0).x * 64 * coarseVoxel;
    CHECK(topMass == Approx(fineMass * fineVoxel).epsilon(1e-5));

    // Both splatters render every level of the odd volume (no read past its cells).
    for (RendererKind kind : {RendererKind::Axis, RendererKind::Sheet})
        for (double pixel : {0.6, 1.5, 3.5}) {
            RenderSettings f = scene.settings();
            f.renderer = kind;
            f.camera.width = f.camera.height = 24;
            f.camera.pixelSize = pixel;
            f.camera.azimuthDeg = 33;
            f.camera.elevationDeg = 21;
            f.quality.lod = LevelOfDetail::threshold(64);
            RenderStats st;
            const Image im = scene.render(f, &st);
            CHECK(st.lodLevel >= 1);
            for (const glm::vec4& p : im.pixels) CHECK((std::isfinite(p.a) && p.a <= 1.0001f));
        }
}

TEST_CASE("lod: X-ray of a constant box keeps its line integrals and its mass", "[lod]") {
    // The box [8, 32)^3 of value c: even bounds, so the 2x level's cells inside are full.
    const float c = 1.5f;
    const Volume v = boxVolume(40, 8, 32, c);
    RenderSettings s;
    s.mode = RenderMode::Xray;
    s.threads = 1;
    s.camera.width = s.camera.height = 64;
    s.camera.pixelSize = 1.0;  // one voxel per pixel: lod 1.5 takes level 1, lod 0 level 0
    const Scene scene(v, s);
    const footprint::FootprintTable& table = scene.impl().table;
    // Interior ray along a volume axis: sum over the columns of c L fp(r^2) = c L (1 + ripple)
    // at either level (the footprint in voxel units is the same function at both), so
    // |X_1 - X_0| <= 2 r1 c L. Mass: each splat's footprint summed over the pixels (pixel
    // size 1 voxel at level 0, 1/2 voxel at level 1) is 1 within the lattice ripple there.
    const double r1 = latticeRipple(table, 1.0), rHalf = latticeRipple(table, 0.5);
    INFO("ripple: unit lattice " << r1 << ", half lattice " << rHalf);
    REQUIRE(r1 < 0.01);
    REQUIRE(rHalf <= r1);
    const double L = 24.0, cL = c * L, mass = c * 24.0 * 24.0 * 24.0;
    const double slack = 1e-5;  // float sums of ~1e3 terms

    for (double az : {0.0, 90.0}) {
        RenderSettings f = s;
        f.camera.azimuthDeg = az;
        RenderStats st0, st1;
        const Image x0 = scene.render(f, &st0);
        f.quality.lod = LevelOfDetail::threshold(1.5);
        const Image x1 = scene.render(f, &st1);
        REQUIRE(st0.lodLevel == 0);
        REQUIRE(st1.lodLevel == 1);
        CHECK(st1.lodSplats == 12u * 12u * 12u);
        const Camera cam(f.camera, v);
        double worst = 0, m0 = 0, m1 = 0;
        int interior = 0;
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const double p0 = x0.at(x, y).r, p1 = x1.at(x, y).r;
                m0 += p0;
                m1 += p1;
                // Interior: the coarse kernels' reach (2 coarse = 4 fine voxels) inside the
                // box's lateral faces at 8 and 31.
                const glm::dvec3 o = cam.ray(x + 0.5, y + 0.5).origin;
                const double a = az == 0.0 ? o.x : o.y;
                if (a < 8 + 4 || a > 31 - 4 || o.z < 8 + 4 || o.z > 31 - 4) continue;
                ++interior;
                CHECK(std::abs(p0 - cL) <= (r1 + slack) * cL);
                CHECK(std::abs(p1 - cL) <= (r1 + slack) * cL);
                worst = std::max(worst, std::abs(p1 - p0));
            }
        CHECK(interior >= 15 * 15);
        CHECK(worst <= 2 * (r1 + slack) * cL);
        CHECK(std::abs(m0 - mass) <= (r1 + slack) * mass);
        CHECK(std::abs(m1 - mass) <= (rHalf + slack) * mass);
        WARN("X-ray, azimuth " << az << ": interior |X1 - X0| " << worst / cL << " of cL (bound "
                               << 2 * r1 << "), mass level 0 " << m0 / mass - 1 << ", level 1 "
                               << m1 / mass - 1);
    }
}

TEST_CASE("lod: dvr of a constant semi-transparent box through the 2x level", "[lod]") {
    // Pre-classified: constant colour k and extinction rho inside the box, so a ray along an
    // axis composites to k (1 - exp(-tau)) exactly (sheet alpha 1 - exp(-tau_k), colour
    // E alpha / tau), tau = rho L (1 + ripple): |I_1 - I_0| <= k exp(-tau_lo) 2 r1 rho L.
    const Volume v = boxVolume(40, 8, 32, 1.0f);
    RenderSettings s;
    s.threads = 1;
    s.quality.earlyTermination = 0;
    s.camera.width = s.camera.height = 64;
    s.camera.pixelSize = 1.0;
    TransferFunction tf;
    tf.points = {
        {0.0f, {0, 0, 0, 0}}, {0.5f, {0.8f, 0.6f, 0.4f, 0.0f}}, {1.0f, {0.8f, 0.6f, 0.4f, 0.05f}}};
    s.transfer = tf;
    const Scene scene(v, s);
    const double rho = -std::log1p(-0.05), L = 24.0, tau = rho * L;
    const double r1 = latticeRipple(scene.impl().table, 1.0);
    RenderStats st0, st1;
    const Image i0 = scene.render(s, &st0);
    RenderSettings f = s;
    f.quality.lod = LevelOfDetail::threshold(1.5);
    const Image i1 = scene.render(f, &st1);
    REQUIRE(st1.lodLevel == 1);
    const Camera cam(s.camera, v);
    const double bound = 0.8 * std::exp(-tau * (1 - r1)) * 2 * (r1 + 1e-5) * tau;
    double worst = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const glm::dvec3 o = cam.ray(x + 0.5, y + 0.5).origin;
            if (o.x < 12 || o.x > 27 || o.z < 12 || o.z > 27) continue;
            const double a0 = i0.at(x, y).r, a1 = i1.at(x, y).r;
            CHECK(a0 == Approx(0.8 * -std::expm1(-tau)).epsilon(2 * r1));
            worst = std::max(worst, std::abs(a1 - a0));
        }
    CHECK(worst <= bound);
    WARN("dvr box: interior |I1 - I0| " << worst << " (bound " << bound << ")");
}

TEST_CASE("lod: X-ray and MIP at level 1 are the full splatter of the box-filtered volume",
          "[lod]") {
    // phantom:32: even dimensions, so the 2x grid has the same centre and bounding sphere and
    // the camera is the same; every voxel with d != 0 is a splat in these modes.
    const Volume v = makeSynthetic("phantom", 32);
    Volume half = makeVolume({16, 16, 16}, 2.0 * v.spacing, "box-filtered phantom");
    half.origin = v.origin + 0.5 * v.spacing;
    for (int K = 0; K < 16; ++K)
        for (int J = 0; J < 16; ++J)
            for (int I = 0; I < 16; ++I) {
                float sum = 0;
                for (int k = 2 * K; k < 2 * K + 2; ++k)
                    for (int j = 2 * J; j < 2 * J + 2; ++j)
                        for (int i = 2 * I; i < 2 * I + 2; ++i) sum += v.at(i, j, k);
                half.at(I, J, K) = sum / 8;
            }
    for (RenderMode mode : {RenderMode::Xray, RenderMode::Mip})
        for (RendererKind kind : {RendererKind::Axis, RendererKind::Sheet}) {
            RenderSettings s;
            s.mode = mode;
            s.renderer = kind;
            s.threads = 2;
            s.camera.width = s.camera.height = 40;
            s.camera.azimuthDeg = 27;
            s.camera.elevationDeg = 14;
            RenderSettings f = s;
            f.quality.lod =
                LevelOfDetail::threshold(1);  // 32^3 at 40^2: a voxel covers 0.72 pixels
            RenderStats st;
            const Image lod = Scene(v, s).render(f, &st);
            REQUIRE(st.lodLevel == 1);
            const Image filtered = Scene(half, s).render(s);
            float peak = 0;
            for (const glm::vec4& p : filtered.pixels) peak = std::max(peak, p.r);
            const ImageMetrics m = compareImages(lod, filtered);
            INFO(toString(mode) << " " << toString(kind));
            CHECK(peak > 0.1f);
            CHECK(m.maxAbs <= 1e-5 * peak);
        }
}

TEST_CASE("lod: a level is used only while a voxel covers fewer pixels than the threshold",
          "[lod]") {
    const Volume v = makeSynthetic("phantom", 32);
    const RenderSettings s = timingView(48, 20, 10);
    const Scene scene(v, s);
    for (RendererKind kind : {RendererKind::Axis, RendererKind::Sheet})
        for (double pixel : {0.3, 0.7, 1.2, 2.5, 9.0}) {
            RenderSettings f = s;
            f.renderer = kind;
            f.camera.pixelSize = pixel;
            RenderStats off;
            const Image full = scene.render(f, &off);
            CHECK(off.lodLevel == 0);
            CHECK(off.lodSplats == off.splats);
            for (double lod : {0.5, 1.0, 2.0, 4.0, 64.0}) {
                f.quality.lod = LevelOfDetail::threshold(lod);
                RenderStats st;
                const Image im = scene.render(f, &st);
                // Smallest L with (1 / pixel) 2^L >= lod, at most the 1^3 level (5 for 32^3).
                int expected = 0;
                while (expected < 5 && std::ldexp(1.0 / pixel, expected) < lod) ++expected;
                INFO(toString(kind) << " pixel " << pixel << " lod " << lod);
                CHECK(st.lodLevel == expected);
                const Scene::Impl* level = &scene.impl();
                for (int l = 0; l < expected; ++l) level = level->coarser();
                CHECK(st.lodSplats == level->splats.size());
                if (expected == 0) {
                    CHECK(im.pixels == full.pixels);  // bit-identical: the same list
                } else {
                    CHECK(st.lodSplats < off.splats);
                }
            }
        }
    // Perspective: the voxel's size at the bounding sphere's nearest depth decides. Fitted
    // eye, 30 degrees: focal = R / sin 15 = 3.86 R, nearest depth 2.86 R, so a voxel covers
    // 48 / (2 tan 15 3.86 R) 3.86 / 2.86 = 1.13 pixels there (0.84 at the volume centre).
    RenderSettings p = s;
    p.camera.projection = Projection::Perspective;
    p.camera.fovDeg = 30;
    const Camera pc(p.camera, v);
    const double near =
        48.0 / (2.0 * std::tan(M_PI / 12) * pc.focal) * pc.focal / (pc.focal - pc.boundingRadius);
    REQUIRE(near == Approx(1.13).epsilon(0.01));
    for (const auto& [lod, expected] : {std::pair{1.0, 0}, {1.2, 1}, {2.2, 1}, {2.3, 2}}) {
        p.quality.lod = LevelOfDetail::threshold(lod);
        RenderStats st;
        scene.render(p, &st);
        INFO("perspective, lod " << lod);
        CHECK(st.lodLevel == expected);
    }
    // The eye inside the volume: every voxel may be large; the full level (the exact path).
    p.camera.distance = 5;
    p.quality.lod = LevelOfDetail::threshold(64);
    RenderStats inside;
    scene.render(p, &inside);
    CHECK(inside.lodLevel == 0);
    CHECK(inside.exactPixels == 48u * 48u);
    // The reference ray caster ignores the knob.
    RenderSettings r = s;
    r.renderer = RendererKind::Reference;
    r.camera.width = r.camera.height = 12;
    RenderStats a, b;
    const Image ra = scene.render(r, &a);
    r.quality.lod = LevelOfDetail::threshold(64);
    const Image rb = scene.render(r, &b);
    CHECK(ra.pixels == rb.pixels);
    CHECK(b.lodLevel == 0);
    // Out of range: an error, not a silent clamp.
    RenderSettings bad = s;
    bad.quality.lod = LevelOfDetail::threshold(-1);
    CHECK_THROWS_AS(scene.render(bad), Error);
    bad.quality.lod = LevelOfDetail::threshold(NAN);
    CHECK_THROWS_AS(scene.render(bad), Error);
    bad.quality.lod = LevelOfDetail::threshold(65);
    CHECK_THROWS_AS(scene.render(bad), Error);
}

TEST_CASE("lod: dvr at level 1 against the reference (the measured cost of the knob)", "[lod]") {
    // phantom:64 at 64^2 (the geometry of phantom:512 at 512^2: a voxel covers 0.58 pixels),
    // the timing transfer function. Level 1 widens every kernel to 2.3 pixels: opaque
    // silhouettes grow and thin shells blur, so its error is far above the full splatter's
    // (docs/speed-vs-accuracy.md "Level of detail" has the figures at full size).
    const Volume v = makeSynthetic("phantom", 64);
    const RenderSettings s = timingView(64, 30, 15);
    const Scene scene(v, s);
    RenderSettings r = s;
    r.renderer = RendererKind::Reference;
    const Image ref = scene.render(r);
    RenderSettings f = s;
    const double full = compareImages(scene.render(f), ref).rmse;
    f.quality.lod = LevelOfDetail::threshold(1);
    RenderStats st;
    const double lod = compareImages(scene.render(f, &st), ref).rmse;
    REQUIRE(st.lodLevel == 1);
    WARN("dvr phantom:64 at 64^2: RMSE full " << full << ", lod 1 " << lod << " (ratio "
                                              << lod / full << ")");
    CHECK(full < 0.005);
    CHECK(lod < 0.15);
    CHECK(lod > full);
}

TEST_CASE("lod: --lod on the command line and in scene files", "[lod][cli]") {
    const std::filesystem::path dir = testTmpDir("lod_cli");
    for (const char* bad : {"-1", "65", "nan", "x", "1e400"}) {
        const RunResult r = runSplat({"render", "synthetic:phantom:16", "--size", "16x16", "--lod",
                                      bad, "-o", (dir / "bad.png").string()});
        INFO(bad << ": " << r.err);
        CHECK(r.status == 2);
        CHECK(r.errLines().size() == 1);
        CHECK(!std::filesystem::exists(dir / "bad.png"));
    }
    const std::string out = (dir / "a.exr").string(), scene = (dir / "s.json").string();
    // A voxel of phantom:32 covers 0.43 of a 24^2 pixel: level 1 (0.87) at --lod 0.8.
    const RunResult r = runSplat({"render", "synthetic:phantom:32", "--size", "24x24", "--lod",
                                  "0.8", "-o", out, "--write-scene", scene});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("level of detail 1:") != std::string::npos);
    const nlohmann::json j = nlohmann::json::parse(readTextFile(scene));
    CHECK(j["lod"] == 0.8);
    const std::string first = readTextFile(out);
    std::filesystem::remove(out);
    const RunResult again = runSplat({"render", "--scene", scene});
    INFO(again.err);
    REQUIRE(again.status == 0);
    CHECK(readTextFile(out) == first);
    // The reference ray caster: one warning, the option reset.
    const RunResult ref = runSplat({"render", "synthetic:phantom:16", "--size", "8x8", "--renderer",
                                    "reference", "--lod", "2", "-o", out});
    CHECK(ref.status == 0);
    REQUIRE(ref.errLines().size() == 1);
    CHECK(ref.errLines()[0].find("--lod applies to the splatters") != std::string::npos);
}

// ---- --lod auto: the level chosen from the error it adds, and the merged kernel
// narrowed so that kernel, pyramid box and pixel filter together are what the pixel-filtered
// reference sees (model/level_of_detail.h, lodFootprint).

namespace {

constexpr double kPi = 3.14159265358979323846;

/// exp(-|x - c|^2 / (2 b^2)) sampled on an n^3 grid of unit spacing, c the centre voxel.
Volume gaussianBlob(int n, double b) {
    Volume v = makeVolume({n, n, n}, {1.0, 1.0, 1.0}, "gaussian blob");
    const double c = 0.5 * (n - 1);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double r2 = (i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c);
                v.at(i, j, k) = float(std::exp(-0.5 * r2 / (b * b)));
            }
    return v;
}

}  // namespace

TEST_CASE("lod auto: the coarsest level whose merged footprints still sum to a constant",
          "[lod]") {
    const double k2 = footprint::Kernel::defaultKernel().variance();  // 0.3279
    CHECK(lodBoxVariance(0) == 0.0);
    CHECK(lodBoxVariance(1) == 0.25);
    CHECK(lodBoxVariance(2) == 1.25);
    // (k^2 - B_L) v^2 + s^2 >= 0.3 (2^L v)^2: level 1 up to v = 0.472, level 2 up to 0.209.
    auto edge = [&](int level) {
        return std::sqrt(0.25 / (kLodAutoSmooth * std::ldexp(1.0, 2 * level) - k2 +
                                 lodBoxVariance(level)));
    };
    CHECK(edge(1) == Approx(0.472).margin(1e-3));
    CHECK(edge(2) == Approx(0.209).margin(1e-3));
    for (double v : {2.0, 1.0, 0.9, 0.6, 0.48})
        CHECK(lodAutoLevel(v, 0.5, k2, 16) == 0);
    CHECK(lodAutoLevel(edge(1) * 0.999, 0.5, k2, 16) == 1);
    CHECK(lodAutoLevel(edge(1) * 1.001, 0.5, k2, 16) == 0);
    CHECK(lodAutoLevel(edge(2) * 0.999, 0.5, k2, 16) == 2);
    CHECK(lodAutoLevel(edge(2) * 1.001, 0.5, k2, 16) == 1);
    CHECK(lodAutoLevel(0.01, 0.5, k2, 3) == 3);  // at most maxLevel
    CHECK(lodAutoLevel(0.0, 0.5, k2, 16) == 0);
    CHECK(lodAutoLevel(INFINITY, 0.5, k2, 16) == 0);
    // The merged footprint: kernel k^2 - B_L (level-0 voxels^2) with the full filter, or the
    // least kernel with the rest taken from the screen low-pass; either way the footprint's
    // variance in pixels^2 is (k^2 - B_L) v^2 + s^2.
    for (int level : {1, 2, 3})
        for (double v : {0.05, 0.1, 0.2}) {
            const LodFootprint f = lodFootprint(k2, level, 0.5, v);
            const double kernel = f.kernelScale * f.kernelScale * std::ldexp(k2, 2 * level);
            INFO("level " << level << ", v " << v);
            CHECK(kernel * v * v + f.lowPass * f.lowPass ==
                  Approx((k2 - lodBoxVariance(level)) * v * v + 0.25).epsilon(1e-12));
            CHECK(kernel >= kLodMinKernel * k2 * (1 - 1e-12));
        }
    CHECK(lodFootprint(k2, 1, 0.5, 0.3).kernelScale ==
          Approx(std::sqrt((k2 - 0.25) / (4 * k2))).epsilon(1e-12));
    CHECK(lodFootprint(k2, 1, 0.5, 0.3).lowPass == 0.5);
}

TEST_CASE("lod auto: X-ray of a Gaussian blob at level 1 is the filtered closed form, mass kept",
          "[lod]") {
    // f = exp(-r^2 / (2 b^2)) on 33^3 voxels, kernel Gaussian sigma 1 (radius 6: the taper is
    // exp(-18)), a voxel covering 0.5 pixels: lodAutoLevel gives level 1 ((1 - 0.25) 0.25 +
    // 0.25 >= 0.3 * 4 * 0.25; level 2 fails). Closed form: level 0 reconstructs f * h0, the
    // Gaussian of variance s^2 = b^2 + 1, whose X-ray through the pixel filter (sigma 0.5
    // pixels) is the 2D Gaussian of variance s^2 / p^2 + 0.25 pixels^2 holding the blob's mass
    // M = (2 pi b^2)^(3/2). Level 1 renders f * D_1 * h_1 through the same filter, D_1 the
    // cell mean (variance 0.25) and h_1 the kernel narrowed to 1 - 0.25: the same variance;
    // it differs from the Gaussian by D_1's fourth cumulant (-1/8 per axis): at the peak
    // 1 - exp(-1/4 / (2 V)) sqrt((V + 1/4) / V) = 6e-4 per axis (V = b^2 + 1 - 1/4 + 4 * 0.25,
    // the filter in voxels), and by the coarse grid's aliasing of the blob, the first alias of
    // its Poisson sum exp(-pi^2 (b^2 + 1) / 4 / 2) = 4e-5 (in coarse voxels^2: (b^2 + 0.25) /
    // 4 of the blob, (1 - 0.25) / 4 + 0.25 of the footprint; b = 1.5 gives 5e-3).
    const double b = 2.5, p = 2.0, sigma = 0.5;
    const Volume v = gaussianBlob(33, b);
    RenderSettings s;
    s.mode = RenderMode::Xray;
    s.kernel = "gaussian";
    s.kernelSigma = 1.0;
    s.kernelRadius = 6.0;
    s.threads = 2;
    s.camera.width = s.camera.height = 24;
    s.camera.azimuthDeg = 30;
    s.camera.elevationDeg = 20;
    s.camera.pixelSize = p;
    s.quality.earlyTermination = 0;
    const Scene scene(v, s);
    const double s2 = (b * b + 1.0) / (p * p) + sigma * sigma;
    const double mass = std::pow(2 * kPi * b * b, 1.5);
    const double peak = mass / (p * p) / (2 * kPi * s2);
    const Camera cam(s.camera, v);
    const glm::dvec3 c = cam.project(v.world(glm::dvec3(16, 16, 16)));
    auto worst = [&](const Image& im, double& sum) {
        double w = 0;
        sum = 0;
        for (int y = 0; y < im.height; ++y)
            for (int x = 0; x < im.width; ++x) {
                const double dx = x + 0.5 - c.x, dy = y + 0.5 - c.y;
                const double e = peak * std::exp(-0.5 * (dx * dx + dy * dy) / s2);
                w = std::max(w, std::abs(double(im.at(x, y).r) - e) / peak);
                sum += im.at(x, y).r;
            }
        return w;
    };
    for (RendererKind kind : {RendererKind::Axis, RendererKind::Sheet}) {
        INFO(toString(kind));
        RenderSettings f = s;
        f.renderer = kind;
        f.quality.ewa = Ewa::On;  // level 0 through the same filter
        RenderStats st0, st1, stOld;
        double sum0 = 0, sum1 = 0, sumOld = 0;
        const double e0 = worst(scene.render(f, &st0), sum0);
        REQUIRE(st0.lodLevel == 0);
        f.quality.ewa = Ewa::Off;  // auto low-passes a merged level itself
        f.quality.lod = LevelOfDetail::automatic();
        const double e1 = worst(scene.render(f, &st1), sum1);
        REQUIRE(st1.lodLevel == 1);
        CHECK(st1.ewaSigma == sigma);
        // Numeric --lod at level 1: the doubled kernel, variance 4 + 0.25 instead of 1 - 0.25.
        f.quality.lod = LevelOfDetail::threshold(1);
        f.quality.ewa = Ewa::On;
        const double eOld = worst(scene.render(f, &stOld), sumOld);
        REQUIRE(stOld.lodLevel == 1);
        WARN(toString(kind) << ": max |image - closed form| / peak: level 0 " << e0
                            << ", level 1 auto " << e1 << ", level 1 --lod 1 " << eOld
                            << "; mass " << sum0 / (mass / (p * p)) - 1 << ", "
                            << sum1 / (mass / (p * p)) - 1);
        CHECK(e0 < 2e-3);
        CHECK(e1 < 1.5e-3);
        CHECK(eOld > 20 * e1);
        // Mass: the image's sum is the blob's mass over the pixel area (the footprints'
        // energy kept through the narrowed kernel and the low-pass).
        CHECK(sum0 == Approx(mass / (p * p)).epsilon(1e-3));
        CHECK(sum1 == Approx(mass / (p * p)).epsilon(1e-3));
    }
}

TEST_CASE("lod auto: a constant slab at level 1 equals full resolution inside", "[lod]") {
    // No cracks and no double counting: every voxel of the slab z in [8, 40) is in exactly one
    // merged cell, so the X-ray through the slab's interior is c T / |w_z| at either level.
    // Level 0 (with EWA, the same filter) within its footprint's lattice ripple, level 1
    // within the ripple its footprint variance allows: at least kLodAutoSmooth (0.3) of its
    // grid spacing squared, 2 exp(-2 pi^2 0.3) = 0.54% per screen axis.
    const int n = 48;
    Volume v = makeVolume({n, n, n}, {1.0, 1.0, 1.0}, "slab");
    const float value = 2.0f;
    for (int k = 8; k < 40; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) v.at(i, j, k) = value;
    RenderSettings s;
    s.mode = RenderMode::Xray;
    s.threads = 2;
    s.camera.width = s.camera.height = 24;
    s.camera.azimuthDeg = 25;
    s.camera.elevationDeg = 60;  // through the slab's faces, obliquely
    s.camera.pixelSize = 3.0;    // a voxel covers 0.33 pixels: level 1
    s.quality.earlyTermination = 0;
    const Scene scene(v, s);
    const Camera cam(s.camera, v);
    for (RendererKind kind : {RendererKind::Axis, RendererKind::Sheet}) {
        RenderSettings f = s;
        f.renderer = kind;
        f.quality.ewa = Ewa::On;
        const Image i0 = scene.render(f);
        f.quality.ewa = Ewa::Off;
        f.quality.lod = LevelOfDetail::automatic();
        RenderStats st;
        const Image i1 = scene.render(f, &st);
        REQUIRE(st.lodLevel == 1);
        double worst0 = 0, worst1 = 0;
        int interior = 0;
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 24; ++x) {
                const Ray r = cam.ray(x + 0.5, y + 0.5);
                // Where the ray crosses the slab's faces, 8 voxels (the merged kernels' and
                // the filter's reach) inside the volume's sides.
                bool inside = true;
                for (double z : {7.5, 39.5}) {
                    const glm::dvec3 q = r.origin + r.dir * ((z - r.origin.z) / r.dir.z);
                    inside = inside && q.x > 8 && q.x < n - 9 && q.y > 8 && q.y < n - 9;
                }
                if (!inside) continue;
                ++interior;
                const double exact = value * 32.0 / std::abs(r.dir.z);
                worst0 = std::max(worst0, std::abs(i0.at(x, y).r / exact - 1));
                worst1 = std::max(worst1, std::abs(i1.at(x, y).r / exact - 1));
            }
        INFO(toString(kind) << ": " << interior << " interior pixels, level 0 " << worst0
                            << ", level 1 " << worst1);
        WARN(toString(kind) << ": slab interior relative error level 0 " << worst0
                            << ", level 1 " << worst1);
        CHECK(interior >= 20);
        CHECK(worst0 < 4e-3);
        CHECK(worst1 < 2 * 2 * std::exp(-2 * kPi * kPi * kLodAutoSmooth));
    }
}

TEST_CASE("lod auto: deterministic, thread-count invariant, and lod 0 where it keeps level 0",
          "[lod]") {
    const Volume v = makeSynthetic("phantom", 32);
    for (RendererKind kind : {RendererKind::Axis, RendererKind::Sheet}) {
        for (RenderMode mode : {RenderMode::Xray, RenderMode::Dvr}) {
            RenderSettings s;
            s.renderer = kind;
            s.mode = mode;
            s.transfer = TransferFunction::preset("ct-soft");
            s.camera.width = s.camera.height = 24;
            s.camera.azimuthDeg = 30;
            s.camera.elevationDeg = 15;
            const Scene scene(v, s);
            // A voxel covering 3, 1 and 0.33 pixels; and perspective.
            for (double pixel : {1.0 / 3.0, 1.0, 3.0}) {
                for (double fov : {0.0, 30.0}) {
                    RenderSettings f = s;
                    f.camera.pixelSize = pixel;
                    f.camera.fovDeg = fov;
                    if (fov > 0) f.camera.distance = 8.0 * 32 * pixel;
                    f.threads = 1;
                    const Image off = scene.render(f);
                    f.quality.lod = LevelOfDetail::automatic();
                    RenderStats st1, st3, again;
                    const Image one = scene.render(f, &st1);
                    f.threads = 3;
                    const Image three = scene.render(f, &st3);
                    const Image repeat = scene.render(f, &again);
                    INFO(toString(kind) << " " << toString(mode) << " pixel " << pixel << " fov "
                                        << fov << ": level " << st1.lodLevel);
                    CHECK(st1.lodLevel == st3.lodLevel);
                    CHECK(compareImages(one, three).maxAbs == 0.0);
                    CHECK(compareImages(three, repeat).maxAbs == 0.0);
                    // A pixel or more per voxel, or dvr (not measured free): level 0 and the
                    // image of lod 0, bit for bit.
                    const bool coarse = mode == RenderMode::Xray && pixel > 1.0;
                    CHECK((st1.lodLevel > 0) == coarse);
                    if (!coarse) CHECK(compareImages(one, off).maxAbs == 0.0);
                }
            }
        }
    }
}

TEST_CASE("lod auto: --lod auto on the command line, in scene files and as a study value",
          "[lod][cli]") {
    const std::filesystem::path dir = testTmpDir("lod_auto_cli");
    const std::string out = (dir / "a.exr").string(), scene = (dir / "s.json").string();
    // phantom:32 at 12^2: a voxel covers 0.22 pixels; X-ray takes level 1.
    const RunResult r = runSplat({"render", "synthetic:phantom:32", "--mode", "xray", "--size",
                                  "12x12", "--lod", "auto", "-o", out, "--write-scene", scene});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("level of detail 1:") != std::string::npos);
    CHECK(r.out.find("(--lod auto)") != std::string::npos);
    const nlohmann::json j = nlohmann::json::parse(readTextFile(scene));
    CHECK(j["lod"] == "auto");
    const std::string first = readTextFile(out);
    std::filesystem::remove(out);
    const RunResult again = runSplat({"render", "--scene", scene});
    INFO(again.err);
    REQUIRE(again.status == 0);
    CHECK(readTextFile(out) == first);
    for (const char* bad : {"automatic", "bricks", "1,2", ""}) {
        const RunResult b = runSplat({"render", "synthetic:phantom:16", "--size", "16x16", "--lod",
                                      bad, "-o", (dir / "bad.png").string()});
        INFO(bad << ": " << b.err);
        CHECK(b.status == 2);
        CHECK(b.errLines().size() == 1);
        // The line names the words --lod takes, not only numbers.
        CHECK(b.err.find("auto or brick") != std::string::npos);
        CHECK(!std::filesystem::exists(dir / "bad.png"));
    }
    const std::filesystem::path report = dir / "study";
    const RunResult st = runSplat({"study", "synthetic:phantom:32", "--mode", "xray", "--size",
                                   "12x12", "--sweep", "lod=0,1,auto", "--views", "30",
                                   "--repeats", "1", "--warmup", "0", "--pixel-filter", "0.5",
                                   "--report", report.string(), "-q"});
    INFO(st.err);
    REQUIRE(st.status == 0);
    const std::string text = readTextFile(report / "study.csv");
    CHECK(text.find("\nauto,") != std::string::npos);
}
