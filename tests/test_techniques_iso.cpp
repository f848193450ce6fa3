// Isosurfaces through the splatters' sheets against the reference's root finding.
#include <catch2/catch.hpp>
#include <cmath>

#include "cli_util.h"
#include "reference_util.h"
#include "techniques_util.h"

using namespace splat;
using namespace splat::test;

namespace {

// Silhouette radius (world) of an iso image: pixels hit cover pi r^2.
double silhouetteRadius(const Image& im, double pixelSize) {
    std::size_t hits = 0;
    for (const auto& p : im.pixels) hits += p.a >= 1.0f;
    return std::sqrt(double(hits) / M_PI) * pixelSize;
}

// The blob's analytic level-set radius (see tests/test_reference.cpp).
double blobRadius(int n, double level, const footprint::Kernel& kernel) {
    double m2 = 0;
    const int steps = 4000;
    for (int q = 0; q <= steps; ++q) {
        const double u = kernel.radius() * q / steps;
        const double w = (q == 0 || q == steps) ? 1 : (q % 2 ? 4 : 2);
        m2 += w * 4.0 * M_PI * u * u * kernel(u) * u * u / 3.0;
    }
    m2 *= kernel.radius() / steps / 3.0;
    const double sb2 = syntheticBlobSigma(n) * syntheticBlobSigma(n), var = sb2 + m2;
    return std::sqrt(2.0 * var * std::log(std::pow(sb2 / var, 1.5) / level));
}

struct IsoCase {
    const char* name;
    int n;
    double level;
};

}  // namespace

TEST_CASE(
    "iso: silhouette radius and hit depth of sphere and blob, splatters against the "
    "reference",
    "[techniques]") {
    const IsoCase cases[] = {{"sphere", 48, 0.5}, {"blob", 32, 0.5}};
    for (const IsoCase& c : cases) {
        const Volume v = makeSynthetic(c.name, c.n);
        RenderSettings s = techniqueSettings(RendererKind::Reference, RenderMode::Iso, 96);
        s.camera.pixelSize = std::string(c.name) == "sphere" ? 0.6 : 0.15;
        s.camera.azimuthDeg = 30;
        s.camera.elevationDeg = 20;
        s.isoLevel = c.level;
        s.quality.slab = 0.25;
        const double analytic = std::string(c.name) == "sphere"
                                    ? syntheticSphereRadius(c.n)
                                    : blobRadius(c.n, c.level, kernelOf(s));
        const Scene refScene(v, s);
        const Image refDepth = refScene.renderIsoDepth(s);
        const Image ref = refScene.render(s);
        const double refRadius = silhouetteRadius(ref, s.camera.pixelSize);
        INFO(c.name << ": analytic radius " << analytic << ", reference silhouette " << refRadius);
        CHECK(std::abs(refRadius - analytic) < 0.1);
        for (RendererKind r : {RendererKind::Sheet, RendererKind::Axis}) {
            s.renderer = r;
            const Scene scene(v, s);
            const Image im = scene.render(s);
            const Image depth = scene.renderIsoDepth(s);
            const double radius = silhouetteRadius(im, s.camera.pixelSize);
            // Hit depth: mean and worst |splatter - reference| over pixels both hit, away from
            // the silhouette (where grazing rays make depth ill-conditioned).
            double sum = 0, worst = 0;
            int both = 0, disagree = 0, total = 0;
            const Camera cam(s.camera, v);
            for (int y = 0; y < im.height; ++y)
                for (int x = 0; x < im.width; ++x) {
                    const bool a = im.at(x, y).a >= 1.0f, b = ref.at(x, y).a >= 1.0f;
                    total += a || b;
                    disagree += a != b;
                    if (!a || !b || impactOf(cam, x, y) > 0.8 * analytic) continue;
                    const double d = std::abs(depth.at(x, y).r - refDepth.at(x, y).r);
                    sum += d;
                    worst = std::max(worst, d);
                    ++both;
                }
            INFO(toString(r) << ": silhouette radius " << radius << ", mean |depth - ref| "
                             << sum / both << ", worst " << worst << ", silhouette pixels "
                             << "disagreeing " << disagree << " of " << total);
            CHECK(both > 500);
            CHECK(std::abs(radius - analytic) < (r == RendererKind::Sheet ? 0.1 : 0.25));
            CHECK(sum / both < (r == RendererKind::Sheet ? 0.05 : 0.3));
            CHECK(worst < (r == RendererKind::Sheet ? 0.2 : 0.8));
            CHECK(double(disagree) / total < 0.02);
        }
        s.renderer = RendererKind::Reference;
    }
}

TEST_CASE("a flag that does not apply to the mode gets a warning line", "[techniques][cli]") {
    const std::string out = (testTmpDir("tech_warn") / "o.png").string();
    struct Case {
        std::vector<std::string> args;
        std::string text;
    };
    const Case cases[] = {
        {{"--mode", "xray", "--shade"}, "shading does not apply to xray"},
        {{"--mode", "mip", "--edges", "1"}, "edge enhancement"},
        {{"--mode", "mip", "--classify", "post"}, "--classify post does not apply"},
        {{"--iso-level", "0.3"}, "--iso-level applies to iso mode only"},
        {{"--ambient", "0.5"}, "without --shade"},
    };
    for (const Case& c : cases) {
        std::vector<std::string> args{"render", "synthetic:blob:8", "--size", "16x16", "-o", out};
        args.insert(args.end(), c.args.begin(), c.args.end());
        const RunResult r = runSplat(args);
        INFO(r.err);
        CHECK(r.status == 0);
        CHECK(r.err.find("splat: warning: " + std::string()) != std::string::npos);
        CHECK(r.err.find(c.text) != std::string::npos);
    }
    // An applicable flag is silent.
    const RunResult ok =
        runSplat({"render", "synthetic:blob:8", "--size", "16x16", "-o", out, "--shade"});
    CHECK(ok.status == 0);
    CHECK(ok.err.empty());
}
