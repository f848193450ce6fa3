// The pixel-filtered reference (reference/pixel_filter.h) and EWA resampling in the
// splatters (footprint/ellipse.h, ewaFootprint), against closed forms: a Gaussian blob's
// X-ray is a Gaussian, and Gaussians convolve to a Gaussian.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>

#include "cli_util.h"
#include "footprint/ellipse.h"
#include "footprint/kernel.h"
#include "reference/pixel_filter.h"
#include "reference_util.h"
#include "splat/image_io.h"
#include "splat/render.h"
#include "splat/synthetic.h"

using namespace splat;
using namespace splat::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

// One voxel of value 1 at the centre of a 17^3 grid of unit spacing.
Volume blob() {
    Volume v = makeVolume({17, 17, 17}, {1.0, 1.0, 1.0}, "one voxel");
    v.at(8, 8, 8) = 1.0f;
    return v;
}

// An X-ray of the blob with a Gaussian kernel of sigma 1 voxel (radius 6: the taper is
// exp(-18) of the peak, so the kernel is the Gaussian), a voxel covering `voxelPixels` pixels.
RenderSettings blobXray(RendererKind renderer, double voxelPixels, int size) {
    RenderSettings s;
    s.renderer = renderer;
    s.mode = RenderMode::Xray;
    s.kernel = "gaussian";
    s.kernelSigma = 1.0;
    s.kernelRadius = 6.0;
    s.camera.width = s.camera.height = size;
    s.camera.azimuthDeg = 30;
    s.camera.elevationDeg = 20;
    s.camera.pixelSize = 1.0 / voxelPixels;
    s.quality.earlyTermination = 0;
    return s;
}

// The closed form: the X-ray of a unit Gaussian of sigma 1 voxel is the 2D Gaussian
// exp(-r^2 / 2) / (2 pi) (r in world units = voxels), of sigma 1 / pixelSize pixels on
// screen; through a pixel filter of sigma f pixels it is a Gaussian of variance
// sigma_img^2 + f^2 with the same integral.
double closedForm(double dx, double dy, double pixelSize, double f) {
    const double si2 = 1.0 / (pixelSize * pixelSize), sc2 = si2 + f * f;
    return si2 / sc2 * std::exp(-0.5 * (dx * dx + dy * dy) / sc2) / (2.0 * kPi);
}

// Largest |image - closed form| over the image, relative to the closed form's peak.
double worstAgainstClosedForm(const Image& im, const Volume& v, const RenderSettings& s,
                              double f) {
    const Camera cam(s.camera, v);
    const glm::dvec3 c = cam.project(v.world(glm::dvec3(8, 8, 8)));
    const double peak = closedForm(0, 0, cam.pixelSize, f);
    double worst = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            const double e = closedForm(x + 0.5 - c.x, y + 0.5 - c.y, cam.pixelSize, f);
            worst = std::max(worst, std::abs(double(im.at(x, y).r) - e) / peak);
        }
    return worst;
}

}  // namespace

TEST_CASE("pixel filter: the filtered reference of a blob's X-ray is the convolved Gaussian",
          "[pixel-filter][reference]") {
    const Volume v = blob();
    for (double voxelPixels : {0.5, 2.0}) {
        RenderSettings s = blobXray(RendererKind::Reference, voxelPixels, 24);
        INFO("voxel covers " << voxelPixels << " pixels");
        // Point sampling is the unfiltered closed form ...
        CHECK(worstAgainstClosedForm(Renderer(v, s).render(), v, s, 0.0) < 2e-4);
        // ... and with the filter, the Gaussian of variance sigma_img^2 + 0.5^2.
        s.quality.pixelFilter = 0.5;
        RenderStats st;
        const Image im = Renderer(v, s).render(&st);
        CHECK(st.pixelSamples >= 4);
        CHECK(st.pixelFilterChange < s.quality.pixelFilterTolerance);
        CHECK(worstAgainstClosedForm(im, v, s, 0.5) < 1e-3);
        // Not the unfiltered one: the test can fail.
        CHECK(worstAgainstClosedForm(im, v, s, 0.0) > 0.02);
    }
}

TEST_CASE("pixel filter: the filtered image converges as the rays per pixel double",
          "[pixel-filter][reference]") {
    // phantom:32 in dvr at 24x24, a voxel 0.6 pixels: edges finer than a pixel.
    const Volume v = makeSynthetic("phantom", 32);
    RenderSettings s;
    s.renderer = RendererKind::Reference;
    s.transfer = TransferFunction::preset("ct-soft");
    s.camera.width = s.camera.height = 24;
    s.camera.azimuthDeg = 30;
    const Renderer r(v, s);
    const Camera cam(s.camera, v);
    const int margin = 2;
    std::vector<Image> filtered;
    for (int n = 2; n <= 16; n *= 2)
        filtered.push_back(filterSupersampled(r.render(supersampledCamera(cam, n, margin)), 24,
                                              24, n, margin, 0.5));
    double peak = 0;
    for (const glm::vec4& p : filtered.back().pixels) peak = std::max(peak, double(p.r));
    std::vector<double> change;
    for (std::size_t k = 1; k < filtered.size(); ++k)
        change.push_back(compareImages(filtered[k], filtered[k - 1]).rmse / peak);
    INFO("RMS change 2->4 " << change[0] << ", 4->8 " << change[1] << ", 8->16 " << change[2]);
    CHECK(change[0] > 1.5 * change[1]);
    CHECK(change[1] > 1.5 * change[2]);
    CHECK(change[2] < 2e-3);
    // The library's loop stops at the first change below the tolerance.
    RenderSettings f = s;
    f.quality.pixelFilter = 0.5;
    f.quality.pixelFilterTolerance = 0.5 * (change[1] + change[2]);
    RenderStats st;
    const Image im = Renderer(v, f).render(&st);
    CHECK(st.pixelSamples == 16);
    CHECK(compareImages(im, filtered[3]).rmse < 1e-6);
}

TEST_CASE("kernel: the per-axis variance of the kernels", "[ewa][kernel]") {
    CHECK(footprint::Kernel::defaultKernel().variance() == Approx(0.32789).epsilon(1e-4));
    CHECK(footprint::Kernel::cubicBSpline(1.0).variance() == Approx(0.3).epsilon(1e-6));
    CHECK(footprint::Kernel::cubicBSpline(2.0).variance() == Approx(1.2).epsilon(1e-6));
    CHECK(footprint::Kernel::gaussian(1.0, 6.0).variance() == Approx(1.0).epsilon(1e-4));
}

TEST_CASE("ewa: footprint parameters are the Gaussian convolved with the low-pass",
          "[ewa][footprint]") {
    // A sheared, anisotropic footprint; the model: the kernel as a Gaussian of variance k2.
    const double k2 = 0.4, R = 2.0 * std::sqrt(k2) * 3.0, lp = 0.7;
    const glm::dvec3 sp(1.0, 2.5, 0.6), w = glm::normalize(glm::dvec3(0.3, 1.0, -0.4));
    const glm::dvec3 ax = glm::normalize(glm::cross(w, glm::dvec3(0, 0, 1))) * 0.8;
    const glm::dvec3 ay = glm::normalize(glm::cross(w, ax)) * 0.8;
    const auto e = footprint::ellipticalFootprint(sp, ax, ay, w, R);
    const auto f = footprint::ewaFootprint(e, k2, lp, R);
    // Section of the Gaussian model between world depths t0, t1 at offset (dx, dy).
    auto section = [&](const footprint::EllipticalFootprint& q, double dx, double dy, double t0,
                       double t1) {
        const double r2 = q.r2(float(dx), float(dy));
        const double g = std::exp(-0.5 * r2 / k2) / (2 * kPi * k2);
        auto phi = [&](double t) {
            return 0.5 * std::erfc(-q.depth(float(t), float(dx), float(dy)) / std::sqrt(2 * k2));
        };
        return q.scale * g * (phi(t1) - phi(t0));
    };
    // Brute-force convolution of e's sections with the low-pass, by quadrature.
    auto convolved = [&](double dx, double dy, double t0, double t1) {
        const double h = 0.05, cut = 5 * lp;
        double sum = 0, wsum = 0;
        for (double u = -cut; u <= cut; u += h)
            for (double v = -cut; v <= cut; v += h) {
                const double g = std::exp(-0.5 * (u * u + v * v) / (lp * lp));
                sum += g * section(e, dx - u, dy - v, t0, t1);
                wsum += g;
            }
        return sum / wsum;
    };
    const double big = 1e3;
    const double peak = section(f, 0, 0, -big, big);
    // Energy kept: the whole footprint's integral over the screen.
    double area = 0, areaF = 0;
    for (double x = -12; x <= 12; x += 0.05)
        for (double y = -12; y <= 12; y += 0.05) {
            area += section(e, x, y, -big, big) * 0.0025;
            areaF += section(f, x, y, -big, big) * 0.0025;
        }
    CHECK(areaF == Approx(area).epsilon(1e-4));
    for (double dx : {0.0, 0.9, -1.7})
        for (double dy : {0.0, 1.3, -0.6})
            for (auto [t0, t1] : {std::pair{-big, big}, {-0.5, 0.5}, {0.3, 1.9}, {-2.2, -0.4}}) {
                INFO(dx << ", " << dy << " depths " << t0 << ".." << t1);
                CHECK(std::abs(section(f, dx, dy, t0, t1) - convolved(dx, dy, t0, t1)) <
                      2e-4 * peak);
            }
    CHECK(f.halfWidth > e.halfWidth);
    CHECK(f.halfHeight > e.halfHeight);
    CHECK(footprint::ewaFootprint(e, k2, 0.0, R).scale == e.scale);  // off: unchanged
    CHECK_THROWS(footprint::ewaFootprint(e, 0.0, lp, R));
    CHECK_THROWS(footprint::ewaFootprint(e, k2, -1.0, R));
}

TEST_CASE("ewa: both splatters' X-ray of a blob is the filtered closed form",
          "[ewa][splatters]") {
    const Volume v = blob();
    for (RendererKind kind : {RendererKind::Axis, RendererKind::Sheet}) {
        for (double voxelPixels : {0.5, 2.0}) {
            INFO(toString(kind) << ", voxel covers " << voxelPixels << " pixels");
            RenderSettings s = blobXray(kind, voxelPixels, 24);
            s.quality.ewa = Ewa::Off;  // the point-sampled splatters (auto would filter 0.5)
            const double plain = worstAgainstClosedForm(Renderer(v, s).render(), v, s, 0.5);
            s.quality.ewa = Ewa::On;
            RenderStats st;
            const Image im = Renderer(v, s).render(&st);
            CHECK(st.ewaSigma == 0.5);
            // The kernel variance is sigma^2 less the taper's exp(-18) share: exact to 1e-3.
            const double ewa = worstAgainstClosedForm(im, v, s, 0.5);
            CHECK(ewa < 2e-3);
            CHECK(plain > 10 * ewa);
            // And the filtered reference (the same closed form, by supersampling).
            RenderSettings r = blobXray(RendererKind::Reference, voxelPixels, 24);
            r.quality.pixelFilter = 0.5;
            CHECK(compareImages(im, Renderer(v, r).render()).maxAbs <
                  2e-3 * closedForm(0, 0, 1.0 / voxelPixels, 0.5));
        }
    }
}

TEST_CASE("ewa: auto is on in xray below a pixel per voxel, else off (bit-identical)",
          "[ewa][splatters]") {
    const Volume v = makeSynthetic("phantom", 32);
    for (RenderMode mode : {RenderMode::Xray, RenderMode::Dvr})
        for (RendererKind kind : {RendererKind::Axis, RendererKind::Sheet})
            for (double pixelSize : {0.5, 2.0}) {  // a voxel covers 2 and 0.5 pixels
                INFO(toString(mode) << ", " << toString(kind) << ", pixel size " << pixelSize);
                RenderSettings s;
                s.renderer = kind;
                s.mode = mode;
                s.transfer = TransferFunction::preset("ct-soft");
                s.camera.width = s.camera.height = 32;
                s.camera.azimuthDeg = 30;
                s.camera.pixelSize = pixelSize;
                s.quality.ewa = Ewa::Off;
                const Image off = Renderer(v, s).render();
                s.quality.ewa = Ewa::Auto;
                RenderStats st;
                const Image autoImage = Renderer(v, s).render(&st);
                const bool on = mode == RenderMode::Xray && pixelSize > 1.0;
                CHECK(st.ewaSigma == (on ? Quality::kEwaDefaultSigma : 0.0));
                CHECK((compareImages(autoImage, off).maxAbs == 0.0) == !on);
            }
}

TEST_CASE("cli: --pixel-filter and --ewa refuse bad values with one line and status 2",
          "[ewa][cli]") {
    const std::filesystem::path dir = testTmpDir("ewa_cli");
    const std::string out = (dir / "o.png").string();
    for (const std::vector<std::string>& bad :
         {std::vector<std::string>{"--pixel-filter", "-1"},
          {"--pixel-filter", "5"},
          {"--pixel-filter", "nan"},
          {"--ewa", "maybe"}}) {
        std::vector<std::string> args{"render", "synthetic:blob:8", "--size", "8x8", "-o", out};
        args.insert(args.end(), bad.begin(), bad.end());
        const RunResult r = runSplat(args);
        INFO(bad[0] << " " << bad[1] << ": " << r.err);
        CHECK(r.status == 2);
        REQUIRE(r.errLines().size() == 1);
        CHECK(r.errLines()[0].rfind("splat: error:", 0) == 0);
        CHECK(r.err.find(bad[0]) != std::string::npos);
        CHECK(!std::filesystem::exists(out));
    }
    const RunResult ok = runSplat({"render", "synthetic:blob:8", "--size", "8x8", "--renderer",
                                   "reference", "--pixel-filter", "0.5", "-o", out});
    CHECK(ok.status == 0);
    CHECK(std::filesystem::exists(out));
}

TEST_CASE("ewa: the default (auto) filters sub-pixel X-ray, and is off elsewhere bit for bit",
          "[ewa][splatters][cli]") {
    CHECK(Quality{}.ewa == Ewa::Auto);
    const std::filesystem::path dir = testTmpDir("ewa_default");
    // phantom:32 at 16x16 (a voxel covers 0.29 pixels) and at 64x64 (1.15 pixels), through
    // the command line: the default against --ewa off and --ewa on.
    for (const char* size : {"16x16", "64x64"})
        for (const char* renderer : {"axis", "sheet"}) {
            INFO(renderer << " at " << size);
            auto frame = [&](const std::vector<std::string>& extra) {
                const std::string out = (dir / (std::string(renderer) + "_" + size + "_" +
                                                std::to_string(extra.size()) +
                                                (extra.empty() ? "" : extra.back()) + ".exr"))
                                            .string();
                std::vector<std::string> args{"render", "synthetic:phantom:32", "--tf", "ct-soft",
                                              "--mode", "xray", "--renderer", renderer,
                                              "--size", size, "--azimuth", "30", "-o", out};
                args.insert(args.end(), extra.begin(), extra.end());
                const RunResult r = runSplat(args);
                INFO(r.err);
                REQUIRE(r.status == 0);
                return readImage(out);
            };
            const Image byDefault = frame({}), off = frame({"--ewa", "off"}),
                        on = frame({"--ewa", "on"});
            const bool subPixel = std::string(size) == "16x16";
            CHECK((compareImages(byDefault, off).maxAbs == 0.0) == !subPixel);
            if (subPixel) CHECK(compareImages(byDefault, on).maxAbs == 0.0);
        }
}

TEST_CASE("truth: the reference an analysis judges against follows the splatters' filter",
          "[ewa][truth]") {
    const Volume v = makeSynthetic("phantom", 32);
    RenderSettings s;
    s.mode = RenderMode::Xray;
    s.camera.width = s.camera.height = 16;  // a voxel covers 0.29 pixels
    const std::vector<CameraParams> views{s.camera};
    CHECK(ewaLowPass(s, v) == Quality::kEwaDefaultSigma);
    CHECK(truthFilter(s, v, views, Truth::Auto) == Quality::kEwaDefaultSigma);
    CHECK(truthFilter(s, v, views, Truth::Point) == 0.0);
    s.quality.ewa = Ewa::Off;  // point-sampled splatters: the point-sampled truth
    CHECK(ewaLowPass(s, v) == 0.0);
    CHECK(truthFilter(s, v, views, Truth::Auto) == 0.0);
    CHECK(truthFilter(s, v, views, Truth::Filtered) == Quality::kEwaDefaultSigma);
    s.quality.ewa = Ewa::Auto;
    s.quality.pixelFilter = 1.0;  // a pixel filter given is the filter of both
    CHECK(ewaLowPass(s, v) == 1.0);
    CHECK(truthFilter(s, v, views, Truth::Auto) == 1.0);
    s.quality.pixelFilter = 0;
    s.mode = RenderMode::Dvr;  // auto leaves dvr alone: its truth stays point-sampled
    CHECK(truthFilter(s, v, views, Truth::Auto) == 0.0);
    s.mode = RenderMode::Xray;
    s.camera.width = s.camera.height = 64;  // 1.15 pixels per voxel
    CHECK(truthFilter(s, v, {s.camera}, Truth::Auto) == 0.0);
    // Any view of a sweep with EWA on makes the sweep's truth filtered.
    CameraParams small = s.camera;
    small.width = small.height = 16;
    CHECK(truthFilter(s, v, {s.camera, small}, Truth::Auto) == Quality::kEwaDefaultSigma);
}
