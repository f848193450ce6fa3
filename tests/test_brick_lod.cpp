// Level of detail per brick and view (`--lod brick`, splat/src/model/brick_lod.h):
// the bricks' levels from the projected voxel size and the pyramid's detail, frames mixing
// levels (the sum of a frame per level in X-ray) against the full-resolution splatter and the
// pixel-filtered reference, mass, thread counts, perspective, a background value b != 0.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "dispatch/dispatch.h"
#include "model/brick_lod.h"
#include "model/level_of_detail.h"
#include "model/scene_impl.h"
#include "splat/metrics.h"
#include "splat/render.h"
#include "splat/scene.h"

using namespace splat;

namespace {

/// 80 x 48 x 48 voxels: x < 48 the constant c, x >= 48 c plus uniform noise of amplitude a
/// (the detail a merged level drops), everything shifted by the background `b`.
Volume halfConstantHalfNoise(float c, float a, float b) {
    Volume v = makeVolume({80, 48, 48}, {1.0, 1.0, 1.0}, "half constant, half noise");
    std::mt19937 rng(27);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int k = 0; k < 48; ++k)
        for (int j = 0; j < 48; ++j)
            for (int i = 0; i < 80; ++i) v.at(i, j, k) = b + c + (i >= 48 ? a * u(rng) : 0.0f);
    v.background = b;
    v.backgroundSource = "test";
    return v;
}

/// 96 x 48 x 48 voxels, everything b plus: a smooth Gaussian blob (8 voxels) centred in the
/// first 48^3 (bricks x 0-2) and uniform noise of amplitude 1 on x >= 64 (bricks x 4-5); the
/// bricks of x in [48, 64) hold nothing.
Volume blobAndNoise(float b) {
    Volume v = makeVolume({96, 48, 48}, {1.0, 1.0, 1.0}, "blob and noise");
    std::mt19937 rng(27);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int k = 0; k < 48; ++k)
        for (int j = 0; j < 48; ++j)
            for (int i = 0; i < 96; ++i) {
                const double x = i - 23.5, y = j - 23.5, z = k - 23.5;
                const float blob =
                    i < 48 ? float(std::exp(-(x * x + y * y + z * z) / 128.0)) : 0.0f;
                v.at(i, j, k) = b + blob + (i >= 64 ? u(rng) : 0.0f);
            }
    v.background = b;
    v.backgroundSource = "test";
    return v;
}

RenderSettings xrayView(double pixelSize, int size) {
    RenderSettings s;
    s.mode = RenderMode::Xray;
    s.threads = 2;
    s.camera.width = s.camera.height = size;
    s.camera.azimuthDeg = 30;
    s.camera.elevationDeg = 20;
    s.camera.pixelSize = pixelSize;
    return s;
}

double imageSum(const Image& im) {
    double sum = 0;
    for (const glm::vec4& p : im.pixels) sum += p.r;
    return sum;
}

/// The bricks' levels of `scene` in the frame `s` (as renderFrame chooses them).
std::vector<std::uint8_t> levelsOf(const Scene& scene, const RenderSettings& s,
                                   const Volume& v) {
    const Scene::Impl& impl = scene.impl();
    const Camera camera(s.camera, v);
    return brickLevels(camera, impl.splats.origin, impl.splats.spacing, v.dims,
                       Quality::kEwaDefaultSigma, impl.kernel.variance(), kLodBrickMaxLevel,
                       &impl.brickDetail());
}

}  // namespace

TEST_CASE("brick lod: smooth bricks go coarse, detailed bricks stay fine, within the full "
          "splatter's error against the filtered reference",
          "[lod]") {
    // A voxel covers 1/3 pixel: the geometric rule allows level 1 everywhere (lodAutoLevel:
    // level 1 up to 0.472 pixels per voxel, level 2 up to 0.209).
    const Volume v = blobAndNoise(0.0f);
    RenderSettings s = xrayView(3.0, 40);
    const Scene scene(v, s);
    const std::vector<std::uint8_t> levels = levelsOf(scene, s, v);
    const BrickDetail& d = scene.impl().brickDetail();
    REQUIRE(d.bricks == glm::ivec3(6, 3, 3));
    CHECK(d.occupied[d.brick(50, 16, 16)] == 0);  // the empty layer
    for (int k = 0; k < 48; k += 16)
        for (int j = 0; j < 48; j += 16) {
            for (int i = 0; i < 48; i += 16) {
                INFO("blob brick at " << i << " " << j << " " << k << ": detail "
                                      << d.detail[d.brick(i, j, k)] << " of field RMS "
                                      << d.fieldRms);
                CHECK(levels[d.brick(i, j, k)] == 1);
            }
            for (int i = 64; i < 96; i += 16) CHECK(levels[d.brick(i, j, k)] == 0);
        }
    // The frame mixes the two levels: the splats of level 0 are those of the level-0 bricks.
    RenderSettings f = s;
    f.quality.lod = LevelOfDetail::perBrick();
    RenderStats st;
    const Image mixed = scene.render(f, &st);
    REQUIRE(st.lodLevelSplats.size() == 2);
    CHECK(st.lodLevel == 1);
    std::size_t fine = 0;
    const SplatList& l0 = scene.impl().splats;
    for (std::size_t q = 0; q < l0.size(); ++q)
        fine += levels[d.brick(l0.i[q], l0.j[q], l0.k[q])] == 0;
    CHECK(st.lodLevelSplats[0] == fine);
    CHECK(st.lodLevelSplats[1] > 0);
    CHECK(st.lodSplats == st.lodLevelSplats[0] + st.lodLevelSplats[1]);
    CHECK(st.lodSplats < l0.size());
    // Full resolution (EWA on at a third of a pixel per voxel: Ewa::Auto) and the filtered
    // reference (sigma 0.5 pixels, the EWA low-pass).
    RenderStats st0;
    const Image full = scene.render(s, &st0);
    REQUIRE(st0.ewaSigma > 0);
    RenderSettings r = s;
    r.renderer = RendererKind::Reference;
    r.quality.pixelFilter = Quality::kEwaDefaultSigma;
    const Image truth = scene.render(r);
    const double eFull = compareImages(full, truth).rmse, eMixed = compareImages(mixed, truth).rmse;
    WARN("blob and noise, 40^2: RMSE against the filtered reference: full + EWA "
         << eFull << ", --lod brick " << eMixed << " (" << st.lodLevelSplats[0] << " + "
         << st.lodLevelSplats[1] << " splats of " << l0.size() << ")");
    CHECK(eMixed <= 1.05 * eFull);
    // Mass: every splat's footprint keeps its integral at any level.
    CHECK(imageSum(mixed) == Approx(imageSum(full)).epsilon(1e-4));
    // Thread counts: the same image bit for bit.
    f.threads = 1;
    const Image one = scene.render(f);
    f.threads = 3;
    const Image three = scene.render(f);
    CHECK(compareImages(one, mixed).maxAbs == 0.0);
    CHECK(compareImages(three, mixed).maxAbs == 0.0);
}

TEST_CASE("brick lod: where every brick takes one level the frame is that level's", "[lod]") {
    // Constant content with little detail everywhere but the faces: at 0.33 pixels per voxel
    // the bricks take level 1 or 0 by their faces; all on level 1 when the content rule is
    // left out. A frame whose bricks all take one level renders that level's own list (no
    // part is copied): the same image as a frame of that level alone.
    const Volume v = halfConstantHalfNoise(1.0f, 0.0f, 0.0f);
    RenderSettings s = xrayView(3.0, 36);
    s.quality.lod = LevelOfDetail::perBrick();
    const Scene scene(v, s);
    const Camera camera(s.camera, v);
    const Scene::Impl& impl = scene.impl();
    const std::vector<std::uint8_t> geometric =
        brickLevels(camera, impl.splats.origin, impl.splats.spacing, v.dims,
                    Quality::kEwaDefaultSigma, impl.kernel.variance(), kLodBrickMaxLevel, nullptr);
    for (std::uint8_t l : geometric) CHECK(l == 1);
    const auto parts = impl.lodParts(geometric);
    REQUIRE(parts.size() == 1);
    CHECK(parts.front().get() == impl.coarser());  // the level itself
    // A mixed choice: one part per level, their splats the level's bricks', none twice.
    std::vector<std::uint8_t> mixed = geometric;
    for (std::size_t b = 0; b < mixed.size(); b += 2) mixed[b] = 0;
    const auto two = impl.lodParts(mixed);
    REQUIRE(two.size() == 2);
    CHECK(two[0]->level == 0);
    CHECK(two[1]->level == 1);
    CHECK(two[0]->splats.size() + 8 * two[1]->splats.size() == impl.splats.size());
    // Cached: the same levels give the same parts.
    CHECK(impl.lodParts(mixed)[1].get() == two[1].get());
}

TEST_CASE("brick lod: perspective, near bricks fine and far bricks coarse", "[lod]") {
    // Two smooth blobs (10 voxels) on the z axis, 112 voxels apart, viewed along z from in front
    // of the near one: the near blob's voxels look 3x larger than the far one's.
    const int nz = 160;
    Volume v = makeVolume({48, 48, nz}, {1.0, 1.0, 1.0}, "two blobs");
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < 48; ++j)
            for (int i = 0; i < 48; ++i) {
                const double x = i - 23.5, y = j - 23.5, z0 = k - 23.5, z1 = k - 135.5;
                v.at(i, j, k) = float(std::exp(-(x * x + y * y + z0 * z0) / 200.0) +
                                      std::exp(-(x * x + y * y + z1 * z1) / 200.0));
            }
    RenderSettings s;
    s.mode = RenderMode::Xray;
    s.threads = 2;
    s.camera.projection = Projection::Perspective;
    s.camera.fovDeg = 40;
    s.camera.lookAtSet = true;
    s.camera.eye = glm::dvec3(23.5 + 8, 23.5 + 6, -40.0);
    s.camera.lookAt = glm::dvec3(23.5, 23.5, 80.0);
    s.camera.upHint = glm::dvec3(0, 1, 0);
    s.camera.width = s.camera.height = 20;
    const Scene scene(v, s);
    // The geometric rule: the near blob's bricks at level 0, the far blob's coarser.
    const Scene::Impl& impl = scene.impl();
    const std::vector<std::uint8_t> geometric =
        brickLevels(Camera(s.camera, v), impl.splats.origin, impl.splats.spacing, v.dims,
                    Quality::kEwaDefaultSigma, impl.kernel.variance(), kLodBrickMaxLevel, nullptr);
    const BrickDetail& d = impl.brickDetail();
    const int nearLevel = geometric[d.brick(16, 16, 16)], farLevel = geometric[d.brick(16, 16, 128)];
    INFO("near brick level " << nearLevel << ", far " << farLevel);
    CHECK(nearLevel == 0);
    CHECK(farLevel >= 1);
    // The whole rule (detail and seams) may keep the far blob finer; the frame stays the
    // full splatter's.
    RenderSettings f = s;
    f.quality.lod = LevelOfDetail::perBrick();
    RenderStats st;
    const Image mixed = scene.render(f, &st);
    REQUIRE(!st.lodLevelSplats.empty());
    CHECK(st.lodLevelSplats[0] > 0);
    RenderSettings e = s;
    e.quality.ewa = Ewa::On;  // level 0 through the same low-pass everywhere
    const Image full = scene.render(e);
    float peak = 0;
    for (const glm::vec4& p : full.pixels) peak = std::max(peak, p.r);
    const ImageMetrics m = compareImages(mixed, full);
    WARN("two blobs in perspective: levels near " << nearLevel << ", far " << farLevel
                                                  << "; max |mixed - full| / peak "
                                                  << m.maxAbs / peak << ", RMSE / peak "
                                                  << m.rmse / peak);
    CHECK(m.rmse < 5e-3 * peak);
    CHECK(m.maxAbs < 2e-2 * peak);
    // Thread counts: bit for bit.
    f.threads = 1;
    CHECK(compareImages(scene.render(f), mixed).maxAbs == 0.0);
}

TEST_CASE("brick lod: a background value b != 0 (a CT in HU): background bricks are empty at "
          "every level and the frame is that of the shifted volume",
          "[lod]") {
    // Air b = -1000 HU: splats hold d - b, so air is no splat at any level; the X-ray
    // integrates f - b. The same field shifted by 1000 (b = 0) takes the same levels and
    // renders the same image.
    const Volume air = blobAndNoise(-1000.0f), up = blobAndNoise(0.0f);
    RenderSettings s = xrayView(3.0, 40);
    s.quality.lod = LevelOfDetail::perBrick();
    const Scene a(air, s), b(up, s);
    const BrickDetail& d = a.impl().brickDetail();
    CHECK(d.occupied[d.brick(50, 16, 16)] == 0);  // air: no splat
    CHECK(d.occupied[d.brick(70, 16, 16)] == 1);
    RenderStats sa, sb;
    const Image ia = a.render(s, &sa), ib = b.render(s, &sb);
    // The same levels (the splat counts differ where d - b rounds to 0 in float at -1000).
    REQUIRE(sa.lodLevelSplats.size() == 2);
    REQUIRE(sb.lodLevelSplats.size() == 2);
    CHECK(std::abs(double(sa.lodLevelSplats[0]) - double(sb.lodLevelSplats[0])) < 10);
    float peak = 0;
    for (const glm::vec4& p : ib.pixels) peak = std::max(peak, p.r);
    CHECK(compareImages(ia, ib).maxAbs <= 1e-3 * peak);
    // Mass kept against full resolution (with EWA, as the merged levels are low-passed).
    RenderSettings full = s;
    full.quality.lod = LevelOfDetail{};
    full.quality.ewa = Ewa::On;
    const Image i0 = a.render(full);
    CHECK(imageSum(ia) == Approx(imageSum(i0)).epsilon(1e-4));
    // The corner sees only air: f - b = 0 at every level.
    CHECK(ia.at(0, 0).r == 0.0f);
}

TEST_CASE("brick lod: a seam through the field costs what the seam rule keeps out", "[lod]") {
    // One constant 16^3 brick at level 1 inside constant level-0 surroundings (the rule would
    // keep it at level 0: its faces hold the field): rendered alone, it differs from the same
    // brick at level 0 by a sawtooth along its faces' projections (brick_lod.h, 3.), while
    // the mass is the same.
    const Volume v = halfConstantHalfNoise(1.0f, 0.0f, 0.0f);
    RenderSettings s = xrayView(3.0, 36);
    s.quality.lod = LevelOfDetail::perBrick();
    const Scene scene(v, s);
    const Scene::Impl& impl = scene.impl();
    const BrickDetail& d = impl.brickDetail();
    std::vector<std::uint8_t> one(d.count(), 0);
    one[d.brick(16, 16, 16)] = 1;
    const Scene::Impl& l1 = *impl.coarser();
    const Scene::Impl at1Part(l1, splatsOfBricks(l1.splats, 1, one, d.bricks), Scene::Impl::Part{});
    std::vector<std::uint8_t> zero(d.count(), 1);
    zero[d.brick(16, 16, 16)] = 0;
    const Scene::Impl at0Part(impl, splatsOfBricks(impl.splats, 0, zero, d.bricks),
                              Scene::Impl::Part{});
    CHECK(at1Part.splats.size() == 8u * 8u * 8u);
    CHECK(at0Part.splats.size() == 16u * 16u * 16u);
    // A frame merging under a tenth of level 0 is level 0 (no copy of the rest).
    CHECK(impl.lodParts(one).size() == 1);
    RenderSettings e = s;
    e.quality.lod = LevelOfDetail{};
    e.quality.ewa = Ewa::On;
    const Image at1 = renderFrame(at1Part, s, nullptr, nullptr),
                at0 = renderFrame(at0Part, e, nullptr, nullptr);
    double peak = 0;
    for (const glm::vec4& p : at0.pixels) peak = std::max(peak, double(p.r));
    CHECK(imageSum(at1) == Approx(imageSum(at0)).epsilon(1e-4));
    const ImageMetrics m = compareImages(at1, at0);
    WARN("one constant brick, level 1 against level 0: max " << m.maxAbs / peak
                                                              << " of its peak");
    CHECK(m.maxAbs > 5e-3 * peak);  // why the seam rule exists
    // And the rule: with the field on every face, that brick stays at level 0.
    const std::vector<std::uint8_t> levels = levelsOf(scene, s, v);
    CHECK(levels[d.brick(16, 16, 16)] == 0);
}
