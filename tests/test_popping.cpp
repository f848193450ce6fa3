// The popping analyzer (splat/popping.h) on volumes where the answer is known: the
// axis-aligned splatter switches its sheets exactly where S^-1 view changes its major axis,
// and that switch is a discontinuity; the image-aligned splatter changes continuously.
#include <catch2/catch.hpp>
#include <cmath>

#include "splat/popping.h"
#include "splat/scene.h"
#include "splat/synthetic.h"

using namespace splat;

namespace {

// A coloured transfer function: post-classified, colours vary along every ray through the
// cube's blurred faces, so the compositing order (the sheet orientation) shows.
TransferFunction colouredTf() {
    TransferFunction tf;
    tf.normalized = true;
    tf.points = {{0.0f, glm::vec4(0, 0, 0, 0)},
                 {0.3f, glm::vec4(1, 0.1f, 0.1f, 0.4f)},
                 {0.6f, glm::vec4(0.1f, 1, 0.1f, 0.7f)},
                 {1.0f, glm::vec4(0.1f, 0.2f, 1, 0.9f)}};
    return tf;
}

RenderSettings cubeSettings(Classification c) {
    RenderSettings s;
    s.transfer = colouredTf();
    s.classification = c;
    s.camera.width = s.camera.height = 48;
    return s;
}

const RendererSeries& series(const PoppingResult& r, RendererKind k) {
    const RendererSeries* s = r.find(k);
    REQUIRE(s != nullptr);
    return *s;
}

std::vector<const PoppingEvent*> eventsOf(const PoppingResult& r, RendererKind k) {
    std::vector<const PoppingEvent*> out;
    for (const PoppingEvent& e : r.events)
        if (e.renderer == k) out.push_back(&e);
    return out;
}

// The assertions of the issue for one sweep through one predicted switch.
void checkOneSwitch(const PoppingResult& r, double expectedSwitch) {
    REQUIRE(r.predictedSwitches.size() == 1);
    CHECK(r.predictedSwitches[0] == Approx(expectedSwitch).margin(1e-6));
    const auto axisEvents = eventsOf(r, RendererKind::Axis);
    REQUIRE(axisEvents.size() == 1);
    const PoppingEvent& e = *axisEvents[0];
    CHECK(e.predicted);
    CHECK(e.angleFrom <= r.predictedSwitches[0]);
    CHECK(e.angleTo >= r.predictedSwitches[0]);
    CHECK(e.sheetAxisBefore != e.sheetAxisAfter);
    CHECK(series(r, RendererKind::Axis).spikeRatio >= 5);
    // A discontinuity: the jump stays >= half its coarse value down to 0.001 degrees.
    const double coarse = e.refinement.front().jump[0];
    for (const RefinementStep& st : e.refinement)
        if (st.width >= 0.001) CHECK(st.jump[0] >= 0.5 * coarse);
    CHECK(e.refinedAngle == Approx(r.predictedSwitches[0]).margin(2 * e.refinedWidth));
    CHECK(std::abs(e.refinedSlope) < 0.2);
    // The image-aligned splatter: no event, no spike.
    CHECK(eventsOf(r, RendererKind::Sheet).empty());
    CHECK(series(r, RendererKind::Sheet).spikeRatio <= 2);
}

}  // namespace

TEST_CASE("popping: post-classified cube, azimuth and elevation sweeps through 45 degrees",
          "[popping]") {
    const Volume v = makeSynthetic("cube", 24);
    const Scene scene(v, cubeSettings(Classification::Post));
    for (auto angle : {Sweep::Angle::Azimuth, Sweep::Angle::Elevation}) {
        Sweep sweep;
        sweep.angle = angle;
        sweep.from = 40;
        sweep.to = 50;
        sweep.step = 0.5;
        sweep.base = scene.settings().camera;
        PoppingOptions o;
        o.refine = 10;  // 0.5 / 2^10 < 0.001 degrees
        const PoppingResult r = analyzePopping(scene, sweep, o);
        REQUIRE(r.angles.size() == 21);
        checkOneSwitch(r, 45.0);
    }
}

TEST_CASE("popping: anisotropic spacing moves the switch to where S^-1 view turns", "[popping]") {
    Volume v = makeSynthetic("cube", 24);
    v.spacing = glm::dvec3(1.0, 1.0, 2.0);
    const Scene scene(v, cubeSettings(Classification::Post));
    // Elevation e looks along (0, cos e, -sin e); in index space (0, cos e, -sin e / 2): the
    // sheets turn from y to z where tan e = 2.
    const double expected = std::atan(2.0) * 180.0 / 3.14159265358979323846;  // 63.43 degrees
    Sweep sweep;
    sweep.angle = Sweep::Angle::Elevation;
    sweep.from = 58;
    sweep.to = 68;
    sweep.step = 0.5;
    sweep.base = scene.settings().camera;
    const PoppingResult r = analyzePopping(scene, sweep, PoppingOptions{});
    checkOneSwitch(r, expected);
    // And the world-space choice (45 degrees) is not where anything happens.
    CHECK(std::abs(r.predictedSwitches[0] - 45.0) > 10);
}

TEST_CASE("popping: the image-aligned splatter's change falls linearly with the angle step",
          "[popping]") {
    // Pre-classified phantom: the axis-aligned splatter still pops (colours differ along
    // rays); the image-aligned one is continuous, so over the refined interval its change
    // falls with the width: >= 100x from 0.5 to 0.001 degrees.
    const Volume v = makeSynthetic("phantom", 32);
    RenderSettings s;
    s.transfer = TransferFunction::preset("ct-soft");
    s.camera.width = s.camera.height = 48;
    const Scene scene(v, s);
    Sweep sweep;
    sweep.base = s.camera;
    PoppingOptions o;
    o.renderers = {RendererKind::Axis, RendererKind::Sheet};  // cheap detection, no reference
    o.refine = 10;
    const PoppingResult r = analyzePopping(scene, sweep, o);
    const auto axisEvents = eventsOf(r, RendererKind::Axis);
    REQUIRE(axisEvents.size() == 1);
    const PoppingEvent& e = *axisEvents[0];
    CHECK(e.predicted);
    double coarse = 0, fine = 0;
    for (const RefinementStep& st : e.refinement) {
        if (st.width == Approx(0.5)) coarse = st.change[1];
        if (st.width >= 0.0009 && st.width <= 0.001) fine = st.change[1];
    }
    REQUIRE(fine > 0);
    CHECK(coarse / fine >= 100);
    CHECK(e.refinedSlope < 0.2);  // the axis-aligned splatter's jump does not fall
}

TEST_CASE("popping: bad sweeps are refused with one line", "[popping]") {
    const Volume v = makeSynthetic("blob", 8);
    const Scene scene(v, RenderSettings{});
    Sweep sweep;
    sweep.step = 0;
    CHECK_THROWS_WITH(analyzePopping(scene, sweep, {}), Catch::Contains("--step > 0"));
    sweep.step = 10;
    CHECK_THROWS_WITH(analyzePopping(scene, sweep, {}), Catch::Contains("at least 3 views"));
    sweep.step = 1;
    PoppingOptions o;
    o.renderers = {RendererKind::Axis, RendererKind::Axis};
    CHECK_THROWS_WITH(analyzePopping(scene, sweep, o), Catch::Contains("twice"));
    o.renderers = {RendererKind::Axis};
    o.progress = [](std::size_t done, std::size_t, const std::string&) { return done < 3; };
    CHECK_THROWS_AS(analyzePopping(scene, sweep, o), Cancelled);
}

TEST_CASE("popping: a sub-pixel X-ray sweep is judged against the pixel-filtered reference",
          "[popping][ewa][truth]") {
    // phantom:32 at 16x16: a voxel covers 0.29 pixels, so the splatters' frames are filtered
    // (EWA, the default auto) and the truth is the pixel-filtered reference (sigma 0.5).
    RenderSettings s;
    s.mode = RenderMode::Xray;
    s.transfer = TransferFunction::preset("ct-soft");
    s.camera.width = s.camera.height = 16;
    Sweep sweep;
    sweep.from = 40;
    sweep.to = 42;
    sweep.step = 1;
    sweep.base = s.camera;
    PoppingOptions o;
    o.renderers = {RendererKind::Axis, RendererKind::Reference};
    o.refine = 0;
    o.flip = false;
    const Volume v = makeSynthetic("phantom", 32);
    const std::vector<CameraParams> views{sweep.camera(40), sweep.camera(41), sweep.camera(42)};
    const Scene filteredScene(v, poppingSettings(s, v, views, Truth::Auto));
    CHECK(filteredScene.settings().quality.pixelFilter == Quality::kEwaDefaultSigma);
    const PoppingResult filtered = analyzePopping(filteredScene, sweep, o);
    CHECK(filtered.truthFilter == Quality::kEwaDefaultSigma);
    // The same sweep judged against the point-sampled reference (--truth point).
    o.truth = Truth::Point;
    const Scene pointScene(v, poppingSettings(s, v, views, Truth::Point));
    const PoppingResult point = analyzePopping(pointScene, sweep, o);
    CHECK(point.truthFilter == 0.0);
    const std::vector<double>& ef = series(filtered, RendererKind::Axis).e;
    const std::vector<double>& ep = series(point, RendererKind::Axis).e;
    REQUIRE(ef.size() == 3);
    REQUIRE(ep.size() == 3);
    for (std::size_t n = 0; n < ef.size(); ++n) {
        INFO("view " << n << ": filtered " << ef[n] << ", point " << ep[n]);
        CHECK(ef[n] < 0.1 * ep[n]);
    }
    // A library Scene without the filter in its settings: the analyser renders the filtered
    // reference itself (view by view), with the same figures.
    o.truth = Truth::Auto;
    const PoppingResult own = analyzePopping(pointScene, sweep, o);
    CHECK(own.truthFilter == Quality::kEwaDefaultSigma);
    for (std::size_t n = 0; n < ef.size(); ++n)
        CHECK(series(own, RendererKind::Axis).e[n] == Approx(ef[n]).epsilon(1e-9));
}

TEST_CASE("popping: rounding is no event on a blob or a sphere (the precision floor)",
          "[popping]") {
    // A smooth, symmetric scene swept where nothing switches: the image-aligned splatter's
    // error jumps are float rounding (~1e-7 of a peak near 1), and the median signal they are
    // judged against is rounding too; the floor of 1e-6 of the peak keeps them from being
    // events.
    for (const char* name : {"blob", "sphere"}) {
        INFO(name);
        const Volume v = makeSynthetic(name, 32);
        RenderSettings s;
        s.camera.width = s.camera.height = 64;
        const Scene scene(v, s);
        Sweep sweep;
        sweep.base = s.camera;
        sweep.from = -6;
        sweep.to = 6;
        sweep.step = 1;
        PoppingOptions o;
        o.flip = false;
        o.refine = 2;
        const PoppingResult r = analyzePopping(scene, sweep, o);
        CHECK(eventsOf(r, RendererKind::Sheet).empty());
        CHECK(eventsOf(r, RendererKind::Reference).empty());
        double peak = 0;
        for (const Image& im : series(r, RendererKind::Reference).thumbnails)
            for (const auto& p : im.pixels)
                peak = std::max({peak, double(p.r), double(p.g), double(p.b)});
        CHECK(peak > 0.05);
        const RendererSeries& sheet = series(r, RendererKind::Sheet);
        CHECK(sheet.threshold >= 1e-6 * peak * 0.99);
        for (double j : sheet.signal) CHECK(j < sheet.threshold);
    }
}

TEST_CASE("popping: events on one interval are refined through views rendered once",
          "[popping]") {
    // Frames by hand: every renderer's image is a ramp in the azimuth, the splatters' jump by
    // 0.5 past 45.2 degrees, so both splatters have their event on [45, 45.5] and bisect
    // through the same views; each view is rendered once for both.
    const Volume geometry = makeSynthetic("phantom", 8);
    RenderSettings s;
    s.camera.width = s.camera.height = 8;
    Sweep sweep;
    sweep.base = s.camera;
    PoppingOptions o;
    o.refine = 4;
    int frames = 0;
    o.renderFrame = [&frames](const RenderSettings& f, RenderStats*) {
        ++frames;
        float v = 0.01f * float(f.camera.azimuthDeg);
        if (f.renderer != RendererKind::Reference && f.camera.azimuthDeg > 45.2) v += 0.5f;
        Image im(f.camera.width, f.camera.height);
        for (glm::vec4& p : im.pixels) p = glm::vec4(v, v, v, 1.0f);
        return im;
    };
    const PoppingResult r = analyzePopping(geometry, s, sweep, o);
    REQUIRE(r.events.size() == 2);
    for (const PoppingEvent& e : r.events) {
        CHECK(e.renderer != RendererKind::Reference);
        CHECK(e.angleFrom == 45.0);
        CHECK(e.angleTo == 45.5);
        CHECK(std::abs(e.refinedAngle - 45.2) <= e.refinedWidth);
        CHECK(e.refinedJump == Approx(0.5).epsilon(1e-3));
    }
    CHECK(r.events[0].refinedAngle == r.events[1].refinedAngle);
    // 21 sweep views and refine + 2 refinement views, each by the three renderers.
    CHECK(frames == 21 * 3 + (o.refine + 2) * 3);
}
