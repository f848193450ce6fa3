// Gaussian renderers (splat/gaussians.h) against closed forms: the 3DGS rasterizer's lone
// Gaussian is the dilated 2D Gaussian of the EWA projection, separate Gaussians composite
// independently, the per-pixel sort equals the global one where the orders agree, the volume
// reference's lone Gaussian is 1 - exp(-tau) of the projected marginal, and the sheets
// converge to the reference as the slab thins.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "splat/gaussians.h"
#include "splat/render.h"
#include "splat/synthetic.h"

using namespace splat;

namespace {

constexpr double kPi = 3.14159265358979323846;

GaussianScene one(glm::vec3 mean, glm::vec3 scale, glm::vec4 q, float opacity, glm::vec3 colour) {
    GaussianScene s;
    s.means = {mean};
    s.scales = {scale};
    s.rotations = {glm::normalize(q)};
    s.opacities = {opacity};
    for (int c = 0; c < 3; ++c) s.sh.push_back((colour[c] - 0.5f) / 0.28209479177387814f);
    return s;
}

GaussianScene merge(const GaussianScene& a, const GaussianScene& b) {
    GaussianScene s = a;
    s.means.insert(s.means.end(), b.means.begin(), b.means.end());
    s.scales.insert(s.scales.end(), b.scales.begin(), b.scales.end());
    s.rotations.insert(s.rotations.end(), b.rotations.begin(), b.rotations.end());
    s.opacities.insert(s.opacities.end(), b.opacities.begin(), b.opacities.end());
    s.sh.insert(s.sh.end(), b.sh.begin(), b.sh.end());
    return s;
}

// An orthographic camera looking along +y at the origin (image right +x, up +z), fixed
// whatever the scene's bounds.
CameraParams ortho(int w, int h, double pixelSize) {
    CameraParams c;
    c.width = w;
    c.height = h;
    c.pixelSize = pixelSize;
    c.lookAtSet = true;
    c.eye = {0, -10, 0};
    c.lookAt = {0, 0, 0};
    c.upHint = {0, 0, 1};
    return c;
}

GaussianRenderOptions with(GaussianRenderer r) {
    GaussianRenderOptions o;
    o.renderer = r;
    return o;
}

double maxDiff(const Image& a, const Image& b) {
    double m = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 4; ++c)
            m = std::max(m, double(std::abs(a.pixels[i][c] - b.pixels[i][c])));
    return m;
}

}  // namespace

TEST_CASE("3dgs: a lone Gaussian is the dilated EWA 2D Gaussian", "[gaussians]") {
    // Scales (0.8, 0.3, 0.5) turned 30 degrees about y (the view axis): the image sees the xz
    // covariance; image y runs along -z.
    const double th = 30 * kPi / 180, ps = 0.05;
    const glm::vec4 q(float(std::cos(th / 2)), 0, float(std::sin(th / 2)), 0);
    const glm::vec3 colour(0.9f, 0.5f, 0.2f);
    const GaussianScene s = one({0, 0, 0}, {0.8f, 0.3f, 0.5f}, q, 0.7f, colour);
    const Image img = renderGaussians(s, ortho(96, 80, ps), with(GaussianRenderer::Rasterizer));
    // Sigma_xz of R diag(s^2) R^T for a rotation by th about y.
    const double c = std::cos(th), sn = std::sin(th), a2 = 0.64, c2 = 0.25;
    const double sxx = c * c * a2 + sn * sn * c2, szz = sn * sn * a2 + c * c * c2;
    const double sxz = -c * sn * a2 + sn * c * c2;
    // Pixels: u = x / ps, v = -z / ps.
    const double A = sxx / (ps * ps) + 0.3, B = -sxz / (ps * ps), C = szz / (ps * ps) + 0.3;
    const double det = A * C - B * B;
    double worst = 0;
    int drawn = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const double dx = 48 - (x + 0.5), dy = 40 - (y + 0.5);
            const double power = -0.5 * (C * dx * dx + A * dy * dy - 2 * B * dx * dy) / det;
            double alpha = std::min(0.99, 0.7 * std::exp(power));
            if (alpha < 1.0 / 255) alpha = 0;
            drawn += alpha > 0;
            const glm::vec4 p = img.at(x, y);
            worst = std::max({worst, std::abs(p.a - alpha), std::abs(p.r - colour.r * alpha),
                              std::abs(p.b - colour.b * alpha)});
        }
    CHECK(drawn > 500);
    CHECK(worst < 2e-6);
    // The centre (a pixel corner at 48, 40): alpha = 0.7 exp(-0.5 (0.25 C + 0.25 A - 0.5 B) / det).
    CHECK(img.at(47, 39).a ==
          Approx(0.7 * std::exp(-0.5 * (0.25 * C + 0.25 * A - 0.5 * B) / det)).epsilon(1e-5));
}

TEST_CASE("every renderer: the perspective centre pixel has alpha min(0.99, o)", "[gaussians]") {
    // The volume model's c makes the optical depth through the projected centre
    // -ln(1 - min(0.99, o)).
    for (float o : {0.6f, 1.0f}) {
        const GaussianScene s =
            one({0.3f, 0.2f, -0.1f}, {0.2f, 0.4f, 0.3f}, {1, 0.2f, 0.1f, 0.3f}, o, {1, 1, 1});
        CameraParams cam;  // orbit about the Gaussian (the scene's centre)
        cam.width = cam.height = 65;
        cam.projection = Projection::Perspective;
        cam.azimuthDeg = 25;
        cam.elevationDeg = 15;
        for (GaussianRenderer r : {GaussianRenderer::Rasterizer, GaussianRenderer::PixelSorted,
                                   GaussianRenderer::Sheet, GaussianRenderer::Reference}) {
            INFO(gaussianRendererName(r) << ", opacity " << o);
            const Image img = renderGaussians(s, cam, with(r));
            CHECK(img.at(32, 32).a == Approx(std::min(0.99f, o)).epsilon(1e-6));
            CHECK(img.at(32, 32).r == Approx(std::min(0.99f, o)).epsilon(1e-6));
            CHECK(img.at(0, 0).a == 0.0f);
        }
    }
}

TEST_CASE("3dgs: separate Gaussians composite independently; any thread count", "[gaussians]") {
    const GaussianScene a =
        one({-1.5f, 0.5f, 0.3f}, {0.2f, 0.3f, 0.1f}, {1, 0.3f, 0, 0}, 0.9f, {1, 0, 0});
    const GaussianScene b =
        one({1.2f, -0.4f, -0.2f}, {0.15f, 0.2f, 0.25f}, {1, 0, 0.4f, 0.1f}, 0.6f, {0, 1, 0.5f});
    const CameraParams cam = ortho(128, 64, 0.05);
    for (GaussianRenderer r : {GaussianRenderer::Rasterizer, GaussianRenderer::PixelSorted,
                               GaussianRenderer::Sheet, GaussianRenderer::Reference}) {
        INFO(gaussianRendererName(r));
        const Image ia = renderGaussians(a, cam, with(r)), ib = renderGaussians(b, cam, with(r));
        const Image both = renderGaussians(merge(a, b), cam, with(r));
        double worst = 0, ink = 0;
        for (std::size_t i = 0; i < both.pixels.size(); ++i) {
            REQUIRE((ia.pixels[i].a == 0 || ib.pixels[i].a == 0));
            for (int c = 0; c < 4; ++c) {
                worst = std::max(
                    worst, double(std::abs(both.pixels[i][c] - ia.pixels[i][c] - ib.pixels[i][c])));
                ink += ia.pixels[i][c] + ib.pixels[i][c];
            }
        }
        CHECK(ink > 100);
        CHECK(worst == 0.0);
    }
    const GaussianScene many = syntheticGaussians("gaussians:random:3000:3");
    CameraParams orbit;
    orbit.width = 96;
    orbit.height = 72;
    orbit.azimuthDeg = 20;
    orbit.projection = Projection::Perspective;
    for (GaussianRenderer r : {GaussianRenderer::Rasterizer, GaussianRenderer::PixelSorted}) {
        GaussianRenderOptions o1 = with(r), o2 = with(r);
        o1.threads = 1;
        o2.threads = 2;
        const Image x = renderGaussians(many, orbit, o1), y = renderGaussians(many, orbit, o2);
        CHECK(maxDiff(x, y) == 0.0);
        double alpha = 0;
        for (const auto& p : x.pixels) alpha += p.a;
        CHECK(alpha > 0.1 * x.pixels.size());
    }
}

TEST_CASE("3dgs-pixel: isotropic Gaussians in orthographic views sort as 3dgs", "[gaussians]") {
    // t* of an isotropic Gaussian on an orthographic ray is the depth of its mean.
    GaussianScene s = syntheticGaussians("gaussians:random:400:5");
    for (auto& sc : s.scales) sc = glm::vec3(sc.x);
    CameraParams cam;
    cam.width = cam.height = 64;
    cam.azimuthDeg = 33;
    cam.elevationDeg = 10;
    const Image a = renderGaussians(s, cam, with(GaussianRenderer::Rasterizer));
    const Image b = renderGaussians(s, cam, with(GaussianRenderer::PixelSorted));
    CHECK(maxDiff(a, b) < 1e-6);
    // Anisotropic ones do not: the orders differ somewhere.
    const GaussianScene t = syntheticGaussians("gaussians:random:400:5");
    CHECK(maxDiff(renderGaussians(t, cam, with(GaussianRenderer::Rasterizer)),
                  renderGaussians(t, cam, with(GaussianRenderer::PixelSorted))) > 1e-3);
}

TEST_CASE("reference and sheet: a lone Gaussian is 1 - exp(-tau) of its marginal", "[gaussians]") {
    const double th = 40 * kPi / 180, ps = 0.05;
    const glm::vec4 q(float(std::cos(th / 2)), 0, float(std::sin(th / 2)), 0);
    const float o = 0.75f;
    const GaussianScene s = one({0, 0, 0}, {0.6f, 0.9f, 0.3f}, q, o, {0.3f, 0.6f, 0.9f});
    const double c = std::cos(th), sn = std::sin(th), a2 = 0.36, c2 = 0.09;
    const double A = (c * c * a2 + sn * sn * c2) / (ps * ps),
                 C = (sn * sn * a2 + c * c * c2) / (ps * ps);
    const double B = -(-c * sn * a2 + sn * c * c2) / (ps * ps), det = A * C - B * B;
    const double tauPeak = -std::log(1.0 - o);
    for (GaussianRenderer r : {GaussianRenderer::Reference, GaussianRenderer::Sheet}) {
        INFO(gaussianRendererName(r));
        const Image img = renderGaussians(s, ortho(80, 64, ps), with(r));
        double worst = 0;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) {
                const double dx = 40 - (x + 0.5), dy = 32 - (y + 0.5);
                const double tau =
                    tauPeak * std::exp(-0.5 * (C * dx * dx + A * dy * dy - 2 * B * dx * dy) / det);
                const double alpha = -std::expm1(-tau);
                worst = std::max({worst, std::abs(img.at(x, y).a - alpha),
                                  std::abs(img.at(x, y).g - 0.6 * alpha)});
            }
        CHECK(worst < 2e-6);
    }
}

TEST_CASE("sheet converges to the reference as the slab thins", "[gaussians]") {
    // Two overlapping Gaussians of different colours, seen at 30 degrees so that they overlap
    // in depth: within a slab their colours mix, the sheet's only error.
    const GaussianScene s = syntheticGaussians("gaussians:pop");
    CameraParams cam;
    cam.width = cam.height = 48;
    cam.azimuthDeg = 30;
    GaussianRenderOptions ref = with(GaussianRenderer::Reference);
    ref.tolerance = 1e-7;
    const Image truth = renderGaussians(s, cam, ref);
    std::vector<double> err;
    for (double h : {0.4, 0.2, 0.1, 0.05}) {
        GaussianRenderOptions o = with(GaussianRenderer::Sheet);
        o.slab = h;
        err.push_back(maxDiff(renderGaussians(s, cam, o), truth));
    }
    for (std::size_t k = 1; k < err.size(); ++k) {
        const double order = std::log2(err[k - 1] / err[k]);
        INFO("slab error " << err[k - 1] << " -> " << err[k] << ", order " << order);
        CHECK(order > 1.7);
        CHECK(order < 2.3);
    }
    CHECK(err[0] > 1e-3);
    // The reference meets its tolerance: 1e-4 against 1e-7.
    GaussianRenderOptions loose = ref;
    loose.tolerance = 1e-4;
    CHECK(maxDiff(renderGaussians(s, cam, loose), truth) < 1e-4);
}

TEST_CASE("a volume's splats as Gaussians: the reference renders the volume's model",
          "[gaussians]") {
    // With a kernel radius of 5 sigma the volume kernel misses 1.5e-5 of the Gaussian's mass, so
    // the Gaussians' density sum is the volume's pre-classified extinction field: the two exact
    // references agree to their tolerances.
    const Volume v = makeSynthetic("blob", 16);
    RenderSettings s;
    s.transfer.normalized = true;
    s.transfer.points = {{0.0f, glm::vec4(0, 0, 0, 0)}, {1.0f, glm::vec4(1, 0.8f, 0.6f, 0.5f)}};
    s.kernelRadius = 5 * 0.65;
    s.renderer = RendererKind::Reference;
    s.quality.referenceTolerance = 1e-5;
    const GaussianScene g = gaussiansFromVolume(v, s);
    REQUIRE(g.size() > 1000);
    CHECK(g.scales[0].x == Approx(0.65));
    CameraParams cam = ortho(40, 40, 0.5);
    cam.lookAt = v.center();
    cam.eye = v.center() + glm::dvec3(0, -30, 0);
    cam.azimuthDeg = 0;
    const Image volumeRef = Renderer(v, s).render(cam);
    GaussianRenderOptions o = with(GaussianRenderer::Reference);
    o.tolerance = 1e-5;
    const Image gaussRef = renderGaussians(g, cam, o);
    double peak = 0;
    for (const auto& p : volumeRef.pixels) peak = std::max(peak, double(p.a));
    const double d = maxDiff(volumeRef, gaussRef);
    INFO("peak alpha " << peak << ", max difference " << d);
    CHECK(peak > 0.3);
    CHECK(d < 2e-4);
}
