// The axis-aligned and image-aligned splatters against closed forms, invariants and the
// reference ray caster (issues: render core, image-aligned splatter, reference).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>

#include "footprint/footprint_table.h"
#include "reference_util.h"
#include "splat/render.h"
#include "splat/synthetic.h"

using namespace splat;
using Catch::Matchers::WithinAbs;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A transfer function with constant colour and opacity per unit length over [lo, hi].
TransferFunction flatTf(float alpha, glm::vec3 colour = glm::vec3(1.0f), float lo = 0.0f,
                        float hi = 1.0f) {
    TransferFunction tf;
    tf.name = "flat";
    tf.points = {{lo, glm::vec4(colour, 0.0f)},
                 {lo + 1e-3f * (hi - lo), glm::vec4(colour, alpha)},
                 {hi, glm::vec4(colour, alpha)}};
    return tf;
}

// One voxel of density 1 in the middle of an n^3 volume.
Volume singleVoxel(int n, glm::dvec3 spacing = glm::dvec3(1.0)) {
    Volume v = makeVolume(glm::ivec3(n), spacing, "single voxel");
    v.at(n / 2, n / 2, n / 2) = 1.0f;
    return v;
}

RenderSettings baseSettings(RendererKind r, RenderMode m, int size = 64) {
    RenderSettings s;
    s.renderer = r;
    s.mode = m;
    s.camera.width = s.camera.height = size;
    s.threads = 2;
    return s;
}

// Impact parameter of pixel (px, py)'s ray from the volume centre (world units).
double impact(const Camera& cam, int px, int py) {
    const Ray r = cam.ray(px + 0.5, py + 0.5);
    const glm::dvec3 d = cam.target - r.origin;
    const double along = glm::dot(d, r.dir);
    return std::sqrt(std::max(0.0, glm::dot(d, d) - along * along));
}

double maxRelDiff(const Image& a, const Image& b, double floor) {
    double worst = 0;
    for (std::size_t n = 0; n < a.pixels.size(); ++n)
        for (int c = 0; c < 4; ++c) {
            const double x = a.pixels[n][c], y = b.pixels[n][c];
            worst = std::max(worst, std::abs(x - y) / std::max(floor, std::abs(y)));
        }
    return worst;
}

const RendererKind kSplatters[] = {RendererKind::Axis, RendererKind::Sheet};

}  // namespace

TEST_CASE("xray of the synthetic sphere is its chord length", "[splatter]") {
    const int n = 96;
    const Volume v = makeSynthetic("sphere", n);
    const double radius = syntheticSphereRadius(n);
    for (RendererKind r : kSplatters)
        for (double az : {0.0, 30.0, 45.0}) {
            RenderSettings s = baseSettings(r, RenderMode::Xray, 96);
            s.camera.azimuthDeg = az;
            s.camera.elevationDeg = az / 3;
            const Image img = render(v, s);
            const Camera cam(s.camera, v);
            double sumRel = 0, worst = 0;
            int count = 0;
            for (int y = 0; y < img.height; ++y)
                for (int x = 0; x < img.width; ++x) {
                    const double b = impact(cam, x, y);
                    if (b > 0.8 * radius) continue;  // away from the silhouette
                    const double chord = 2.0 * std::sqrt(radius * radius - b * b);
                    const double rel = std::abs(img.at(x, y).r - chord) / chord;
                    sumRel += rel;
                    worst = std::max(worst, rel);
                    ++count;
                }
            INFO(toString(r) << " azimuth " << az << ": mean rel " << sumRel / count << " worst "
                             << worst);
            REQUIRE(count > 500);
            CHECK(sumRel / count < 0.01);
            CHECK(worst < 0.03);  // the voxelised ball's staircase
        }
}

TEST_CASE("xray of the synthetic blob is the Gaussian line integral", "[splatter]") {
    const int n = 64;
    const Volume v = makeSynthetic("blob", n);
    const double sb = syntheticBlobSigma(n);
    for (RendererKind r : kSplatters)
        for (double az : {0.0, 37.0}) {
            RenderSettings s = baseSettings(r, RenderMode::Xray, 64);
            s.camera.azimuthDeg = az;
            s.camera.elevationDeg = 20;
            // The point-sampled line integral: a voxel covers < 1 pixel, where EWA auto would
            // filter (test_ewa.cpp checks the filtered closed form).
            s.quality.ewa = Ewa::Off;
            const Image img = render(v, s);
            const Camera cam(s.camera, v);
            double worst = 0;
            for (int y = 0; y < img.height; ++y)
                for (int x = 0; x < img.width; ++x) {
                    const double b = impact(cam, x, y);
                    if (b > 2.0 * sb) continue;
                    const double exact = sb * std::sqrt(2 * kPi) * std::exp(-b * b / (2 * sb * sb));
                    worst = std::max(worst, std::abs(img.at(x, y).r - exact) / exact);
                }
            INFO(toString(r) << " azimuth " << az);
            CHECK(worst < 0.01);
        }
}

TEST_CASE("one kernel in dvr composites to k (1 - exp(-rho fp))", "[splatter]") {
    // Anisotropic spacing and an oblique view: the footprint is an ellipse.
    const Volume v = singleVoxel(9, glm::dvec3(1.0, 1.3, 2.0));
    const float alpha = 0.9f;
    const glm::vec3 k(0.8f, 0.5f, 0.25f);
    const footprint::FootprintTable table(footprint::Kernel::defaultKernel());
    for (RendererKind r : kSplatters)
        for (double slab : {2.0, 1.0, 0.3}) {
            RenderSettings s = baseSettings(r, RenderMode::Dvr, 48);
            s.transfer = flatTf(alpha, k);
            s.camera.azimuthDeg = 27;
            s.camera.elevationDeg = 14;
            s.camera.pixelSize = 0.2;
            s.quality.slab = slab;
            s.quality.earlyTermination = 0;
            const Image img = render(v, s);
            const Camera cam(s.camera, v);
            const double rho = -std::log(1.0 - alpha);
            double worst = 0;
            for (int y = 0; y < img.height; ++y)
                for (int x = 0; x < img.width; ++x) {
                    const test::KernelLine l =
                        test::kernelLine(v, cam.ray(x + 0.5, y + 0.5), glm::dvec3(4, 4, 4));
                    const double fp = l.r < table.radius() ? table.exact(l.r) / l.vLen : 0.0;
                    const double a = 1.0 - std::exp(-rho * fp);
                    for (int c = 0; c < 3; ++c)
                        worst = std::max(worst, std::abs(img.at(x, y)[c] - k[c] * a));
                    worst = std::max(worst, std::abs(img.at(x, y).a - a));
                }
            INFO(toString(r) << " slab " << slab);
            CHECK(worst < (r == RendererKind::Axis ? 1e-5 : 1e-4));
        }
}

TEST_CASE("the image-aligned slabs' optical depths sum to the footprint", "[splatter]") {
    // With opacity small enough that exp is linear, the composited alpha of the sheets is the
    // sum of the slab sections; it must not depend on the slab thickness.
    const Volume v = singleVoxel(7);
    RenderSettings s = baseSettings(RendererKind::Axis, RenderMode::Xray, 40);
    s.camera.pixelSize = 0.15;
    s.camera.azimuthDeg = 33;
    s.camera.elevationDeg = -21;
    const Image full = render(v, s);
    s.renderer = RendererKind::Sheet;
    for (double slab : {4.0, 1.0, 0.37, 0.1}) {
        s.quality.slab = slab;
        const Image sections = render(v, s);
        float peak = 0;
        for (const auto& p : full.pixels) peak = std::max(peak, p.r);
        INFO("slab " << slab);
        CHECK(maxRelDiff(sections, full, peak) < 1e-5);  // relative to the peak
    }
}

TEST_CASE("front-to-back equals back-to-front, and any thread count gives the same bytes",
          "[splatter]") {
    const Volume v = makeSynthetic("phantom", 48);
    for (RendererKind r : kSplatters)
        for (Classification c : {Classification::Pre, Classification::Post}) {
            RenderSettings s = baseSettings(r, RenderMode::Dvr, 96);
            s.transfer = TransferFunction::preset("ct-soft");
            s.classification = c;
            s.camera.azimuthDeg = 52;
            s.camera.elevationDeg = 12;
            s.quality.earlyTermination = 0;
            s.threads = 1;
            const Image ftb1 = render(v, s);
            s.threads = 2;
            const Image ftb2 = render(v, s);
            REQUIRE(ftb1.pixels.size() == ftb2.pixels.size());
            CHECK(std::memcmp(ftb1.pixels.data(), ftb2.pixels.data(),
                              ftb1.pixels.size() * sizeof(glm::vec4)) == 0);
            s.order = CompositeOrder::BackToFront;
            const Image btf = render(v, s);
            double worst = 0;
            for (std::size_t n = 0; n < btf.pixels.size(); ++n)
                for (int ch = 0; ch < 4; ++ch)
                    worst =
                        std::max(worst, double(std::abs(btf.pixels[n][ch] - ftb1.pixels[n][ch])));
            INFO(toString(r) << (c == Classification::Pre ? " pre" : " post"));
            CHECK(worst < 1e-5);
        }
}

TEST_CASE("early termination changes the image by less than its threshold", "[splatter]") {
    const Volume v = makeSynthetic("phantom", 48);
    for (RendererKind r : kSplatters) {
        RenderSettings s = baseSettings(r, RenderMode::Dvr, 64);
        s.transfer = flatTf(0.3f, glm::vec3(0.9f, 0.7f, 0.5f), 0.5f, 2.0f);
        s.quality.earlyTermination = 0;
        const Image exact = render(v, s);
        s.quality.earlyTermination = 0.05;
        RenderStats st;
        const Image fast = render(v, s, &st);
        double worst = 0;
        for (std::size_t n = 0; n < exact.pixels.size(); ++n)
            worst = std::max(worst, double(std::abs(exact.pixels[n].r - fast.pixels[n].r)));
        CHECK(worst <= 0.05);
        CHECK(st.culledSplats > 0);
    }
}

TEST_CASE("opacity 0 gives the background exactly; opacity 1 stays finite", "[splatter]") {
    const Volume v = makeSynthetic("phantom", 32);
    for (RendererKind r : kSplatters) {
        RenderSettings s = baseSettings(r, RenderMode::Dvr, 32);
        s.background = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
        s.transfer = flatTf(0.0f);
        const Image clear = render(v, s);
        for (const auto& p : clear.pixels) REQUIRE(p == s.background);
        for (Classification c : {Classification::Pre, Classification::Post}) {
            s.classification = c;
            s.transfer = flatTf(1.0f, glm::vec3(1.0f), 0.0f, 2.0f);
            const Image opaque = render(v, s);
            bool finite = true;
            for (const auto& p : opaque.pixels)
                for (int ch = 0; ch < 4; ++ch)
                    finite = finite && std::isfinite(p[ch]) && p[ch] <= 1.0f + 1e-6f;
            CHECK(finite);
            CHECK(opaque.at(16, 16).a > 0.999f);
        }
    }
}

TEST_CASE("empty volume, a 1x1x1 volume and a 1x1 image render", "[splatter]") {
    for (RendererKind r : kSplatters)
        for (RenderMode m : {RenderMode::Dvr, RenderMode::Xray, RenderMode::Mip}) {
            RenderSettings s = baseSettings(r, m, 16);
            s.transfer = flatTf(0.5f);
            const Volume empty = makeVolume(glm::ivec3(8), glm::dvec3(1.0), "empty");
            const Image e = render(empty, s);
            for (const auto& p : e.pixels) REQUIRE((m == RenderMode::Dvr ? p.a : p.r) == 0.0f);
            Volume one = makeVolume(glm::ivec3(1), glm::dvec3(1.0), "one");
            one.data[0] = 1.0f;
            const Image o = render(one, s);
            CHECK(o.at(8, 8).r > 0.0f);
            s.camera.width = s.camera.height = 1;
            const Image tiny = render(makeSynthetic("sphere", 16), s);
            CHECK(tiny.pixels.size() == 1);
            CHECK(std::isfinite(tiny.pixels[0].r));
        }
}

TEST_CASE("impossible settings are refused with a clear message", "[splatter]") {
    // (iso is rendered by the splatters: tests/test_techniques_iso.cpp)
    const Volume v = makeSynthetic("sphere", 16);
    RenderSettings s = baseSettings(RendererKind::Axis, RenderMode::Dvr);
    s.renderer = RendererKind::Sheet;
    s.quality.slab = 0;
    CHECK_THROWS_WITH(render(v, s), Catch::Contains("slab"));
    s.quality.slab = std::nan("");
    CHECK_THROWS_WITH(render(v, s), Catch::Contains("slab"));
    s.quality.slab = 1;
    s.camera.width = 0;
    CHECK_THROWS_WITH(render(v, s), Catch::Contains("image size"));
}

TEST_CASE("mip of one kernel is its peak along the ray", "[splatter]") {
    // The sheet value is the mean of f over the ray's path through the sheet; for thin
    // slabs it tends to the maximum of f along the ray, h(r).
    const Volume v = singleVoxel(9);
    RenderSettings s = baseSettings(RendererKind::Sheet, RenderMode::Mip, 32);
    s.camera.pixelSize = 0.25;
    s.quality.slab = 0.05;
    const Image img = render(v, s);
    const footprint::Kernel k = footprint::Kernel::defaultKernel();
    const Camera cam(s.camera, v);
    const test::KernelLine centre = test::kernelLine(v, cam.ray(16.5, 16.5), glm::dvec3(4));
    CHECK_THAT(img.at(16, 16).r, WithinAbs(k(centre.r), 0.01 * k(0)));
}

TEST_CASE("no seams between slabs on a constant-density cube", "[splatter]") {
    // Deep inside a cube of constant density the field is 1 up to the kernel's ripple, so
    // every interior ray through the same length of cube has the same optical depth.
    const int n = 40;
    Volume v = makeVolume(glm::ivec3(n), glm::dvec3(1.0), "cube");
    for (int k = 2; k < n - 2; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) v.at(i, j, k) = 1.0f;
    for (double slab : {1.0, 0.5}) {
        RenderSettings s = baseSettings(RendererKind::Sheet, RenderMode::Dvr, 64);
        s.transfer = flatTf(0.02f);
        s.quality.slab = slab;
        s.camera.elevationDeg = 90;  // looking down z through the slab of constant length
        s.camera.pixelSize = 0.37;
        s.quality.earlyTermination = 0;
        const Image img = render(v, s);
        double lo = 1e9, hi = 0;
        for (int y = 8; y < 56; ++y)
            for (int x = 8; x < 56; ++x) {
                lo = std::min(lo, double(img.at(x, y).a));
                hi = std::max(hi, double(img.at(x, y).a));
            }
        INFO("slab " << slab << ": alpha in [" << lo << ", " << hi << "]");
        CHECK((hi - lo) / hi < 0.01);
    }
}

TEST_CASE("splatters against the reference ray caster", "[splatter][accuracy]") {
    struct Case {
        const char* volume;
        int n;
        const char* tf;
        double axisBound, sheetBound;
        bool converges;  // the error falls as the slab thins
    };
    // Bounds: RMSE over the image, dvr colour in [0, 1]; measured values are ~2-3x lower.
    const Case cases[] = {{"blob", 32, "gray-ramp", 0.01, 0.01, true},
                          // The antialiased ball (the binary one had one colour,
                          // so every sheet order was exact to 1e-5).
                          {"sphere", 32, "gray-ramp", 5e-4, 3e-4, true},
                          {"phantom", 64, "ct-soft", 0.02, 0.02, true}};
    for (const Case& c : cases) {
        const Volume v = makeSynthetic(c.volume, c.n);
        RenderSettings s = baseSettings(RendererKind::Reference, RenderMode::Dvr, 64);
        s.transfer = TransferFunction::preset(c.tf);
        s.camera.azimuthDeg = 30;
        s.quality.earlyTermination = 0;
        s.quality.referenceTolerance = 1e-5;
        const Image ref = render(v, s);
        s.renderer = RendererKind::Axis;
        const ImageMetrics axis = compareImages(render(v, s), ref);
        s.renderer = RendererKind::Sheet;
        double previous = 1e9;
        for (double slab : {2.0, 1.0, 0.5, 0.25}) {
            s.quality.slab = slab;
            const ImageMetrics sheet = compareImages(render(v, s), ref);
            INFO(c.volume << " sheet slab " << slab << " rmse " << sheet.rmse << " (axis "
                          << axis.rmse << ")");
            CHECK(sheet.rmse < c.sheetBound);
            if (c.converges) CHECK(sheet.rmse < previous);  // converges as the slab thins
            previous = sheet.rmse;
        }
        INFO(c.volume << " axis rmse " << axis.rmse);
        CHECK(axis.rmse < c.axisBound);
    }
}

TEST_CASE("shading: normals point out of a sphere; ambient 1 reproduces the unshaded image",
          "[splatter][shading]") {
    const Volume v = makeSynthetic("blob", 32);
    TransferFunction tf = flatTf(0.05f);
    const SplatList s = classify(v, tf, RenderMode::Dvr, Classification::Pre, 2.0, true);
    REQUIRE(s.nx.size() == s.size());
    const glm::dvec3 c = v.center();
    int checked = 0;
    for (std::size_t n = 0; n < s.size(); n += 7) {
        const glm::dvec3 out = s.world(n) - c;
        if (glm::length(out) < 3.0 || glm::length(out) > 10.0) continue;
        const double cosine = glm::dot(glm::normalize(out), glm::dvec3(s.nx[n], s.ny[n], s.nz[n]));
        REQUIRE(cosine > 0.99);  // -grad of a Gaussian blob points away from its centre
        ++checked;
    }
    CHECK(checked > 100);
    for (RendererKind r : kSplatters) {
        RenderSettings base = baseSettings(r, RenderMode::Dvr, 48);
        base.transfer = tf;
        const Image plain = render(v, base);
        base.shading.enabled = true;
        base.shading.ambient = 1.0f;
        base.shading.diffuse = base.shading.specular = 0.0f;
        const Image flat = render(v, base);
        CHECK(maxRelDiff(flat, plain, 1e-3) < 1e-6);
        base.shading.ambient = 0.2f;
        base.shading.diffuse = 0.8f;
        const Image lit = render(v, base);
        // Facing the light at the centre: n.l ~ 1 so the centre keeps its brightness,
        // while the limb (n.l ~ 0) darkens to about the ambient share.
        CHECK(lit.at(24, 24).r == Approx(plain.at(24, 24).r).epsilon(0.1));
        CHECK(lit.at(24, 24).r > plain.at(24, 24).r * 0.8);
    }
}

TEST_CASE("perspective views: splatters agree with each other and with the reference",
          "[splatter][perspective]") {
    const Volume v = makeSynthetic("blob", 32);
    RenderSettings s = baseSettings(RendererKind::Axis, RenderMode::Xray, 48);
    s.camera.projection = Projection::Perspective;
    s.camera.fovDeg = 40;
    s.camera.azimuthDeg = 25;
    s.camera.elevationDeg = 15;
    const Image axis = render(v, s);
    s.renderer = RendererKind::Sheet;
    const Image sheet = render(v, s);
    float peak = 0;
    for (const auto& p : axis.pixels) peak = std::max(peak, p.r);
    REQUIRE(peak > 1.0f);
    CHECK(maxRelDiff(sheet, axis, peak) < 1e-5);
    s.renderer = RendererKind::Reference;
    const Image ref = render(v, s);
    // The per-splat local affine footprint (EWA Jacobian) is exact at the splat centre;
    // its error off-centre is a fraction of (kernel radius / eye distance).
    CHECK(compareImages(axis, ref).maxAbs < 5e-4 * peak);  // measured 1.9e-4
    s.mode = RenderMode::Dvr;
    s.transfer = TransferFunction::preset("gray-ramp");
    for (RendererKind r : kSplatters) {
        s.renderer = r;
        const Image dvr = render(v, s);
        s.renderer = RendererKind::Reference;
        const ImageMetrics m = compareImages(dvr, render(v, s));
        INFO(toString(r) << " perspective dvr rmse " << m.rmse);
        CHECK(m.rmse < 2e-4);  // measured 3.4e-5 (axis), 9.5e-6 (sheet)
    }
}

TEST_CASE("early splat elimination: what an opaque front hides changes no pixel it covers",
          "[splatter]") {
    // Looking along +y (azimuth 0, elevation 0) at a front slab j < 3 dense enough that its
    // pixels reach alpha = 1 exactly: everything behind it (random densities) must leave
    // those pixels bit for bit as without it, and front-to-back splatting must skip it
    // (whole bricks before listing, runs before projecting, splats before binning).
    const int n = 40;
    Volume front = makeVolume(glm::ivec3(n), glm::dvec3(1.0), "front");
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < n; ++i) front.at(i, j, k) = 1.0f;
    Volume both = front;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> d(0.2f, 1.0f);
    std::size_t behind = 0;
    for (int k = 4; k < n - 4; ++k)
        for (int j = 3; j < n; ++j)
            for (int i = 4; i < n - 4; ++i, ++behind) both.at(i, j, k) = d(rng);
    for (RendererKind r : kSplatters) {
        RenderSettings s = baseSettings(r, RenderMode::Dvr, 64);
        s.transfer = flatTf(1.0f, glm::vec3(0.8f, 0.6f, 0.4f), 0.1f, 1.0f);
        s.order = CompositeOrder::FrontToBack;
        const Image alone = render(front, s);
        RenderStats st;
        const Image all = render(both, s, &st);
        std::size_t covered = 0;
        for (std::size_t p = 0; p < alone.pixels.size(); ++p)
            if (alone.pixels[p].a == 1.0f) {
                ++covered;
                REQUIRE(all.pixels[p] == alone.pixels[p]);
            }
        INFO(toString(r) << ": " << covered << " covered pixels, " << st.culledSplats
                         << " culled of " << behind << " behind");
        CHECK(covered > 500);  // of ~1380 pixels the front face covers
        CHECK(st.culledSplats >= behind * 9 / 10);
    }
}
