// StopThePop's temporal FLIP (splat/warp.h) and the reference depth it warps with
// (splat/depth.h): the depth of symmetric scenes is their centre's; the warp of a textured
// plane between two views is exact up to the bilinear sampling (its error falls with the
// resolution); a camera that does not move gives FLIP_k = 0 exactly; a smooth volume's
// reference has FLIP_1 near zero, and the 3DGS rasterizer's FLIP_1 where two Gaussians swap
// order is far above the reference's.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "gaussian_pop_util.h"
#include "reference/reference_frame.h"
#include "splat/depth.h"
#include "splat/gaussians.h"
#include "splat/popping.h"
#include "splat/scene.h"
#include "splat/synthetic.h"
#include "splat/warp.h"

using namespace splat;

namespace {

// A textured plane: two thin Gaussians (1e-3 thick along y) of different colours side by
// side in the plane y = 0, which faces the camera at azimuth 0. Their opacity across the
// plane does not depend on the view, so the plane's image moves with the exact flow.
GaussianScene texturedPlane() {
    GaussianScene g;
    g.means = {{-0.3f, 0.0f, 0.1f}, {0.35f, 0.0f, -0.15f}};
    g.scales = {{0.5f, 1e-3f, 0.3f}, {0.25f, 1e-3f, 0.45f}};
    g.rotations = {{1, 0, 0, 0}, {1, 0, 0, 0}};
    g.opacities = {0.9f, 0.8f};
    g.shDegree = 0;
    const float c0 = 1.0f / (2.0f * 0.28209479f);  // SH DC giving colour 0.5 + 0.5 = 1
    g.sh = {c0, -1.6f, -1.6f, -1.6f, -0.5f, c0};
    return g;
}

GaussianRenderOptions referenceOptions() {
    GaussianRenderOptions o;
    o.renderer = GaussianRenderer::Reference;
    o.tolerance = 1e-6;
    return o;
}

// RMS over the valid pixels and RGB of warped - later.
double warpError(const Image& later, const WarpedFrame& w) {
    double sum = 0;
    for (std::size_t p = 0; p < later.pixels.size(); ++p)
        if (w.valid[p])
            for (int c = 0; c < 3; ++c) {
                const double d = double(w.image.pixels[p][c]) - double(later.pixels[p][c]);
                sum += d * d;
            }
    return std::sqrt(sum / double(3 * w.validCount));
}

double planeWarpError(int size, Projection projection, std::size_t* valid = nullptr,
                      bool free = false) {
    const GaussianScene scene = texturedPlane();
    CameraParams a;
    a.width = a.height = size;
    a.projection = projection;
    a.azimuthDeg = 4;
    a.elevationDeg = 3;
    CameraParams b = a;
    b.azimuthDeg = 10;
    b.elevationDeg = -2;
    if (free) {  // free cameras: off-centre look-at points, eyes in front of the plane
        a.lookAtSet = b.lookAtSet = true;
        a.eye = {0.4, -3.0, 0.3};
        a.lookAt = {0.1, 0.0, 0.05};
        b.eye = {-0.3, -2.8, -0.2};
        b.lookAt = {0.0, 0.0, -0.05};
    }
    const Image ia = renderGaussians(scene, a, referenceOptions());
    const Image ib = renderGaussians(scene, b, referenceOptions());
    const Volume geometry = scene.geometry();
    WarpOptions wo;
    wo.border = size / 16;
    const WarpedFrame w = warpFrame(ia, gaussianReferenceDepth(scene, a), Camera(a, geometry), ib,
                                    gaussianReferenceDepth(scene, b), Camera(b, geometry), wo);
    if (valid) *valid = w.validCount;
    return warpError(ib, w);
}

const RendererSeries& seriesOf(const PoppingResult& r, RendererKind k) {
    const RendererSeries* s = r.find(k);
    REQUIRE(s != nullptr);
    return *s;
}

// synthetic:blob:32 (the default grey ramp, dvr) at 48 x 48 with the three volume renderers.
PoppingResult blobPopping(const std::vector<CameraParams>& views) {
    static const Scene scene = [] {
        RenderSettings s;
        s.camera.width = s.camera.height = 48;
        return Scene(makeSynthetic("blob", 32), s);
    }();
    PoppingOptions o;
    o.refine = 0;
    return analyzePopping(scene, views, o);
}

std::vector<CameraParams> azimuths(int count, double step) {
    std::vector<CameraParams> views;
    for (int n = 0; n < count; ++n) {
        CameraParams c;
        c.width = c.height = 48;
        c.azimuthDeg = 20 + n * step;
        views.push_back(c);
    }
    return views;
}

}  // namespace

TEST_CASE("temporal flip: the median-opacity depth", "[temporal]") {
    // A lone isotropic Gaussian (sigma 0.4, opacity 0.9) seen through its centre: the optical
    // depth along the ray is tau(t) = (tau_inf / 2) (1 + erf((t - t*) / (sigma sqrt 2))) with
    // tau_inf = -ln(1 - 0.9) (splat/gaussians.h's model), and t_1/2 is where 1 - exp(-tau)
    // is half of 0.9: in front of the centre, since opacity saturates.
    GaussianScene g = texturedPlane();
    g.means.resize(1);
    g.scales = {{0.4f, 0.4f, 0.4f}};
    g.rotations.resize(1);
    g.opacities = {0.9f};
    g.sh.resize(3);
    CameraParams c;
    c.width = c.height = 33;  // pixel 16's ray passes through the centre
    c.azimuthDeg = 30;
    c.elevationDeg = 20;
    for (Projection pr : {Projection::Orthographic, Projection::Perspective}) {
        c.projection = pr;
        const Image gd = gaussianReferenceDepth(g, c);
        const Ray ray = Camera(c, g.geometry()).ray(16.5, 16.5);
        const double tStar = glm::dot(glm::dvec3(g.means[0]) - ray.origin, ray.dir);
        const double t = gd.at(16, 16).r, tauInf = std::log(10.0);
        const double tau = 0.5 * tauInf * (1 + std::erf((t - tStar) / (0.4 * std::sqrt(2.0))));
        CHECK(gd.at(16, 16).a == 1.0f);
        CHECK(t < tStar);
        CHECK(-std::expm1(-tau) == Approx(0.45).epsilon(1e-4));
        // Symmetric about the centre: mirrored pixels have the same depth.
        for (int x = 0; x < 33; ++x)
            CHECK(gd.at(x, 16).r == Approx(gd.at(32 - x, 16).r).margin(1e-5));
    }
    // A thin plane's depth is the plane's, whatever its opacity: the ray meets y = 0 at
    // t = -origin.y / dir.y.
    const GaussianScene plane = texturedPlane();
    c.projection = Projection::Orthographic;
    c.azimuthDeg = 15;
    const Image pd = gaussianReferenceDepth(plane, c);
    const Camera pc(c, plane.geometry());
    int valid = 0;
    for (int y = 0; y < 33; ++y)
        for (int x = 0; x < 33; ++x)
            if (pd.at(x, y).a > 0) {
                ++valid;
                const Ray r = pc.ray(x + 0.5, y + 0.5);
                CHECK(pd.at(x, y).r == Approx(-r.origin.y / r.dir.y).margin(2e-3));
            }
    CHECK(valid > 100);

    // The blob volume, symmetric about its centre: the centre ray's depth lies in front of
    // the centre, by less than the blob's extent; mirrored pixels have the same depth up to
    // the voxel lattice, which the oblique view does not mirror (0.005 measured).
    RenderSettings s;
    s.camera = c;
    const Scene blob(makeSynthetic("blob", 32), s);
    const Image vd = referenceDepth(blob, c);
    const Camera vc(c, blob.volume());
    const Ray vr = vc.ray(16.5, 16.5);
    const double centre = glm::dot(blob.volume().center() - vr.origin, vr.dir);
    REQUIRE(vd.at(16, 16).a == 1.0f);
    CHECK(vd.at(16, 16).r < centre);
    CHECK(vd.at(16, 16).r > centre - 4);
    for (int x = 0; x < 33; ++x) {
        CHECK(vd.at(x, 16).a == vd.at(32 - x, 16).a);
        CHECK(vd.at(x, 16).r == Approx(vd.at(32 - x, 16).r).margin(0.02));
    }
    // mip has no depth.
    s.mode = RenderMode::Mip;
    const Scene mip(makeSynthetic("blob", 16), s);
    for (const glm::vec4& p : referenceDepth(mip, c).pixels) CHECK(p.a == 0);
}

TEST_CASE("reference depth: skipping the empty bricks changes no depth", "[temporal]") {
    // Pre-classified, the depth march takes the samples outside the field's occupied bricks as
    // 0 without evaluating them: the same sums, so the same depths bit for bit, orthographic
    // and perspective, on a volume with empty space around and inside it.
    for (const Projection projection : {Projection::Orthographic, Projection::Perspective}) {
        RenderSettings s;
        s.transfer = TransferFunction::preset("ct-bone");
        s.camera.width = s.camera.height = 48;
        s.camera.azimuthDeg = 33;
        s.camera.elevationDeg = 21;
        s.camera.projection = projection;
        const Scene scene(makeSynthetic("ct-phantom", 40), s);
        const Camera camera(s.camera, scene.volume());
        const Image skipped = dvrMedianDepth(scene, camera, true);
        const Image full = dvrMedianDepth(scene, camera, false);
        int valid = 0, empty = 0;
        for (std::size_t p = 0; p < full.pixels.size(); ++p) {
            (full.pixels[p].a > 0 ? valid : empty) += 1;
            CHECK(skipped.pixels[p] == full.pixels[p]);
        }
        CHECK(valid > 300);
        CHECK(empty > 100);
    }
}

TEST_CASE("temporal flip: a textured plane warps exactly, up to the sampling", "[temporal]") {
    // Orthographic: the warp's error falls with the resolution (bilinear resampling of the
    // plane's image), 1.2e-3 at 32^2 to 2.8e-4 at 128^2. Perspective: the volumetric
    // model's density scale follows the direction to each Gaussian's mean, so the plane's
    // opacity is not quite a rigid texture there (the flow itself is exact: next test); the
    // error stays about 1e-3 and falls more slowly.
    std::size_t v32 = 0, v128 = 0;
    const double o32 = planeWarpError(32, Projection::Orthographic, &v32),
                 o64 = planeWarpError(64, Projection::Orthographic),
                 o128 = planeWarpError(128, Projection::Orthographic, &v128);
    CHECK(v32 > 50);
    CHECK(v128 > 1000);
    CHECK(o32 < 2e-3);
    CHECK(o64 < 0.6 * o32);
    CHECK(o128 < 0.6 * o64);
    const double p32 = planeWarpError(32, Projection::Perspective),
                 p128 = planeWarpError(128, Projection::Perspective);
    CHECK(p32 < 3e-3);
    CHECK(p128 < 0.8 * p32);
    // Free orthographic cameras (1.3e-3 at 64^2, 5.2e-4 at 128^2).
    std::size_t vf = 0;
    CHECK(planeWarpError(64, Projection::Orthographic, &vf, true) < 2e-3);
    CHECK(vf > 300);
}

TEST_CASE("temporal flip: the flow is exact for free perspective cameras", "[temporal]") {
    // Frames whose colour is the world point each pixel shows (its ray at its depth): the
    // earlier frame warped to the later view must show the later frame's points. The points
    // lie on the plane, so the bilinear interpolation between them stays on it: measured
    // worst errors 3.1e-5 (32^2) and 2.1e-5 (128^2) world units on a plane a unit wide (the
    // depth's float storage and the plane's 1e-3 thickness).
    const GaussianScene plane = texturedPlane();
    auto worstError = [&](int size) {
        CameraParams a;
        a.width = a.height = size;
        a.projection = Projection::Perspective;
        a.lookAtSet = true;
        a.eye = {0.4, -3.0, 0.3};
        a.lookAt = {0.1, 0.0, 0.05};
        CameraParams b = a;
        b.eye = {-0.3, -2.8, -0.2};
        b.lookAt = {0.0, 0.0, -0.05};
        const Volume geometry = plane.geometry();
        const Camera ca(a, geometry), cb(b, geometry);
        const Image da = gaussianReferenceDepth(plane, a), db = gaussianReferenceDepth(plane, b);
        auto points = [](const Image& depth, const Camera& cam) {
            Image im(depth.width, depth.height);
            for (int y = 0; y < depth.height; ++y)
                for (int x = 0; x < depth.width; ++x) {
                    const Ray r = cam.ray(x + 0.5, y + 0.5);
                    im.at(x, y) =
                        glm::vec4(glm::vec3(r.origin + double(depth.at(x, y).r) * r.dir), 1.0f);
                }
            return im;
        };
        const Image pa = points(da, ca), pb = points(db, cb);
        const WarpedFrame w = warpFrame(pa, da, ca, pb, db, cb);
        CHECK(w.validCount > std::size_t(size * size / 4));
        double worst = 0;
        for (std::size_t p = 0; p < pb.pixels.size(); ++p)
            if (w.valid[p])
                worst = std::max(worst, double(glm::length(w.image.pixels[p] - pb.pixels[p])));
        return worst;
    };
    const double e32 = worstError(32), e128 = worstError(128);
    CHECK(e32 < 1e-4);
    CHECK(e128 < 1e-4);
}

TEST_CASE("temporal flip: a camera that does not move gives FLIP_k = 0 exactly", "[temporal]") {
    const PoppingResult r = blobPopping(azimuths(9, 0.0));
    for (const RendererSeries& x : r.series) {
        REQUIRE(x.flipWarp1.size() == 8);
        REQUIRE(x.flipWarp7.size() == 2);
        for (double v : x.flipWarp1) CHECK(v == 0.0);
        for (double v : x.flipWarp7) CHECK(v == 0.0);
        CHECK(x.flipWarp1Mean == 0.0);
        CHECK(x.flipWarp7Mean == 0.0);
    }
}

TEST_CASE("temporal flip: a smooth volume's reference has FLIP_1 near zero", "[temporal]") {
    // 1 degree steps: measured 0.0052 (FLIP_1) and 0.022 (FLIP_7) for every renderer of the
    // blob; a sweep of 7 views has no FLIP_7.
    const PoppingResult r = blobPopping(azimuths(10, 1.0));
    const RendererSeries& ref = seriesOf(r, RendererKind::Reference);
    CHECK(ref.flipWarp1.size() == 9);
    CHECK(ref.flipWarp7.size() == 3);
    CHECK(ref.flipWarp1Mean < 0.01);
    CHECK(ref.flipWarp7Mean < 0.04);
    CHECK(ref.flipWarp7Mean > ref.flipWarp1Mean);  // 7 steps change more than one
    for (const RendererSeries& x : r.series) CHECK(x.flipWarp1Mean < 0.01);
    const PoppingResult seven = blobPopping(azimuths(7, 1.0));
    for (const RendererSeries& x : seven.series) {
        CHECK(x.flipWarp1.size() == 6);
        CHECK(x.flipWarp7.empty());
        CHECK(x.flipWarp7Mean == -1.0);
    }
}

TEST_CASE("temporal flip: 3dgs's FLIP_1 where two Gaussians swap is far above the reference's",
          "[temporal][gaussians]") {
    // gaussians:pop swaps its centres' depth order at azimuth 0: measured FLIP_1 0.176 for
    // 3dgs on the interval [-0.5, 0.5] against 0.0078 for the reference (0.011 and 0.008 on
    // the other intervals).
    const GaussianScene& scene = test::popScene();
    const RenderSettings settings = test::popSettings();
    const Sweep sweep = test::popSweep(settings);
    PoppingOptions o;
    o.refine = 0;
    o.renderers = {RendererKind::Axis, RendererKind::Reference};
    o.renderFrame = [&scene](const RenderSettings& s, RenderStats*) {
        GaussianRenderOptions g;
        g.renderer = s.renderer == RendererKind::Axis ? GaussianRenderer::Rasterizer
                                                      : GaussianRenderer::Reference;
        return renderGaussians(scene, s.camera, g);
    };
    o.depthFrame = [&scene](const CameraParams& c) { return gaussianReferenceDepth(scene, c); };
    const PoppingResult r = analyzePopping(scene.geometry(), settings, sweep, o);
    const RendererSeries& raster = seriesOf(r, RendererKind::Axis);
    const RendererSeries& ref = seriesOf(r, RendererKind::Reference);
    REQUIRE(raster.flipWarp1.size() == 11);
    const std::size_t pop = 5;  // [-0.5, 0.5]
    CHECK(raster.flipWarp1[pop] > 10 * ref.flipWarp1[pop]);
    for (std::size_t n = 0; n < raster.flipWarp1.size(); ++n) {
        CHECK(ref.flipWarp1[n] < 0.01);
        if (n != pop) CHECK(raster.flipWarp1[n] < 0.02);
    }
    // Without a depth callback, frames from renderFrame have no temporal FLIP.
    o.depthFrame = nullptr;
    const PoppingResult none = analyzePopping(scene.geometry(), settings, sweep, o);
    CHECK(none.series[0].flipWarp1.empty());
    CHECK(none.series[0].flipWarp1Mean == -1.0);
}

TEST_CASE("temporal flip: splat popping prints and reports FLIP_1 and FLIP_7", "[temporal][cli]") {
    const std::filesystem::path dir = test::testTmpDir("temporal_flip_cli");
    std::filesystem::remove_all(dir);
    const std::vector<std::string> base = {
        "popping", "synthetic:blob:16", "--size", "32x32", "--from", "0", "--to", "8", "--step",
        "1",       "--refine",          "0",      "-q"};
    std::vector<std::string> args = base;
    args.insert(args.end(), {"--report", (dir / "on").string()});
    const test::RunResult on = test::runSplat(args);
    INFO(on.err);
    REQUIRE(on.status == 0);
    CHECK(on.out.find("FLIP1 warp") != std::string::npos);
    const nlohmann::json j = nlohmann::json::parse(test::readTextFile(dir / "on" / "summary.json"));
    CHECK(j["renderers"]["reference"]["flip_warp_1"].get<double>() < 0.01);
    CHECK(j["renderers"]["reference"]["flip_warp_7"].is_number());
    CHECK(j["options"]["warp_flip"] == true);
    // The report's plot of FLIP_1, and the values in metrics.csv (row 1: axis, interval 0).
    const std::string html = test::readTextFile(dir / "on" / "report.html");
    CHECK(html.find("ꟻLIP₁ of frames warped with the exact flow") != std::string::npos);
    const std::string csv = test::readTextFile(dir / "on" / "metrics.csv");
    const std::string row =
        csv.substr(csv.find('\n') + 1, csv.find('\n', csv.find('\n') + 1) - csv.find('\n') - 1);
    CHECK(row.rfind("axis,0,", 0) == 0);
    CHECK(row.substr(row.size() - 2) != ",,");  // flipWarp1 and flipWarp7 measured
    args = base;
    args.insert(args.end(), {"--no-warp-flip", "--report", (dir / "off").string()});
    const test::RunResult off = test::runSplat(args);
    REQUIRE(off.status == 0);
    const nlohmann::json k =
        nlohmann::json::parse(test::readTextFile(dir / "off" / "summary.json"));
    CHECK(k["renderers"]["reference"]["flip_warp_1"].is_null());
    CHECK(k["options"]["warp_flip"] == false);
    CHECK(test::readTextFile(dir / "off" / "report.html").find("ꟻLIP₁ of frames warped") ==
          std::string::npos);
}
