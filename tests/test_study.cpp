// Speed-accuracy studies, convergence orders and "model only what the scene needs".
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <memory>

#include "splat/render.h"
#include "splat/study.h"
#include "splat/synthetic.h"

using namespace splat;

TEST_CASE("study: knobs parse, unknown knobs and values are refused", "[study]") {
    const StudyKnob k = parseKnob("slab=2,1,0.5");
    CHECK(k.name == "slab");
    CHECK(k.values.size() == 3);
    CHECK_THROWS_WITH(parseKnob("bogus=1"), Catch::Contains("unknown study knob"));
    CHECK_THROWS_WITH(parseKnob("slab=abc"), Catch::Contains("not a number"));
    CHECK_THROWS_WITH(parseKnob("slab"), Catch::Contains("KNOB=V1"));
    CHECK_THROWS(parseKnob("renderer=axis,warp"));
    RenderSettings s;
    applyKnob(s, "size", "64x32");
    CHECK((s.camera.width == 64 && s.camera.height == 32));
    applyKnob(s, "footprint-res", "256");
    CHECK(s.quality.footprintResolution == 256);
    CHECK(isSceneKnob("kernel"));
    CHECK_FALSE(isSceneKnob("slab"));
}

TEST_CASE("study: Pareto marking and order fitting", "[study]") {
    std::vector<StudyPoint> p(4);
    p[0].msMedian = 1, p[0].rmse = 1;      // fastest: on the front
    p[1].msMedian = 2, p[1].rmse = 0.5;    // on the front
    p[2].msMedian = 3, p[2].rmse = 0.7;    // dominated by p[1]
    p[3].msMedian = 10, p[3].rmse = 0.01;  // most accurate: on the front
    markPareto(p);
    CHECK(p[0].pareto);
    CHECK(p[1].pareto);
    CHECK_FALSE(p[2].pareto);
    CHECK(p[3].pareto);
    const std::vector<double> h{1, 0.5, 0.25}, e{3, 0.75, 0.1875};
    CHECK(fitOrder(h, e) == Approx(2.0).epsilon(1e-12));
}

TEST_CASE("study: a small sweep measures, marks the front and writes its report", "[study]") {
    auto v = std::make_shared<const Volume>(makeSynthetic("phantom", 24));
    RenderSettings base;
    base.camera.width = base.camera.height = 32;
    base.transfer = TransferFunction::preset("ct-soft");
    base.threads = 2;
    StudyOptions o;
    o.sweeps = {parseKnob("renderer=axis,sheet"), parseKnob("slab=1,0.5"),
                parseKnob("footprint-res=64,4096")};
    o.repeats = 2;
    o.warmup = 0;
    o.referenceStep = 0.25;
    o.referenceTolerance = 1e-4;
    const std::filesystem::path dir = std::filesystem::path(SPLAT_TEST_TMP) / "study";
    std::filesystem::remove_all(dir);
    o.cacheDir = (dir / "cache").string();
    // Called after every frame (done counts them) and polled inside frames (same done).
    std::size_t calls = 0, lastDone = 0;
    o.progress = [&](std::size_t done, std::size_t, const std::string&) {
        calls += done != lastDone;
        lastDone = done;
        return true;
    };
    StudyResult r = runStudy(v, base, o);
    REQUIRE(r.points.size() == 6);  // axis: the slab knob is measured once
    CHECK(calls == 12);
    bool anyPareto = false;
    for (const StudyPoint& p : r.points) {
        INFO(p.label());
        CHECK(std::isfinite(p.rmse));
        CHECK(p.rmse > 0);
        CHECK(p.msMedian > 0);
        CHECK(p.splats > 0);
        CHECK(p.footprintPixels > 0);
        anyPareto = anyPareto || p.pareto;
    }
    CHECK(anyPareto);
    // A coarse footprint table costs accuracy: 64 entries against 4096.
    auto find = [&](const std::string& label) {
        for (const StudyPoint& p : r.points)
            if (p.label() == label) return p.rmse;
        return -1.0;
    };
    CHECK(find("renderer=axis footprint-res=64") > find("renderer=axis footprint-res=4096"));
    writeStudyReport(r, dir.string(), "splat study (test)");
    for (const char* f : {"study.csv", "study.json", "pareto.svg", "pareto.png"})
        CHECK(std::filesystem::file_size(dir / f) > 100);
    // The reference is cached: a second study reads it instead of rendering it.
    CHECK(std::distance(std::filesystem::directory_iterator(dir / "cache"),
                        std::filesystem::directory_iterator()) == 1);
    o.progress = nullptr;
    StudyResult again = runStudy(v, base, o);
    CHECK(again.points[0].rmse == Approx(r.points[0].rmse).epsilon(1e-6));
    o.progress = [](std::size_t, std::size_t, const std::string&) { return false; };
    CHECK_THROWS_AS(runStudy(v, base, o), Cancelled);
}

TEST_CASE("convergence: the image-aligned splatter is of order 2 in slab thickness",
          "[study][convergence]") {
    auto v = std::make_shared<const Volume>(makeSynthetic("phantom", 32));
    RenderSettings base;
    base.camera.width = base.camera.height = 40;
    base.camera.azimuthDeg = 30;
    base.camera.elevationDeg = 10;
    base.transfer = TransferFunction::preset("ct-soft");
    base.threads = 2;
    ConvergenceOptions o;
    o.slabs = {2, 1, 0.5};
    o.referenceSteps = {0.5, 0.25};
    o.sizes = {16, 32};
    const std::vector<ConvergenceSeries> c = studyConvergence(v, base, o);
    const ConvergenceSeries* slab = nullptr;
    for (const auto& s : c)
        if (s.parameter == "slab") slab = &s;
    REQUIRE(slab);
    INFO("errors " << slab->error[0] << " " << slab->error[1] << " " << slab->error[2]);
    CHECK(slab->order == Approx(2.0).margin(0.3));
    for (std::size_t i = 0; i + 1 < slab->error.size(); ++i)
        CHECK(slab->error[i] / slab->error[i + 1] > 3.0);  // about 4 per halving
}

TEST_CASE("frames model only what the scene needs, and say so", "[study][stats]") {
    const Volume v = makeSynthetic("phantom", 24);
    for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet}) {
        RenderSettings s;
        s.renderer = r;
        s.camera.width = s.camera.height = 32;
        s.threads = 2;
        RenderStats st;
        (void)render(v, s, &st);
        INFO(toString(r));
        CHECK(st.normals == 0);          // unshaded: no gradients
        CHECK(st.pathScalePixels == 0);  // orthographic: no per-pixel path scales
        CHECK_FALSE(st.perspective);
        CHECK(st.exactPixels == 0);
        CHECK(st.splats < st.voxels);  // zero-opacity voxels classified away
        s.shading.enabled = true;
        (void)render(v, s, &st);
        CHECK(st.normals == st.splats);
        s.shading.enabled = false;
        s.camera.projection = Projection::Perspective;
        (void)render(v, s, &st);
        CHECK(st.perspective);
        CHECK(st.pathScalePixels == 32u * 32u);
        CHECK(st.exactPixels == 0);  // the eye is far from every kernel
    }
}

TEST_CASE("study: a setting with EWA on is judged against the pixel-filtered reference",
          "[study][ewa][truth]") {
    // phantom:32 X-ray at 16x16: a voxel covers 0.29 pixels, so ewa=auto filters the frames.
    auto v = std::make_shared<const Volume>(makeSynthetic("phantom", 32));
    RenderSettings base;
    base.mode = RenderMode::Xray;
    base.camera.width = base.camera.height = 16;
    base.transfer = TransferFunction::preset("ct-soft");
    StudyOptions o;
    o.sweeps = {parseKnob("renderer=axis"), parseKnob("ewa=off,auto")};
    o.repeats = 1;
    o.warmup = 0;
    o.referenceStep = 0.25;
    o.referenceTolerance = 1e-4;
    auto byEwa = [](const StudyResult& r, const std::string& value) -> const StudyPoint& {
        for (const StudyPoint& p : r.points)
            for (const auto& [k, val] : p.knobs)
                if (k == "ewa" && val == value) return p;
        FAIL("no point ewa=" << value);
        return r.points.front();
    };
    const StudyResult judged = runStudy(v, base, o);
    REQUIRE(judged.points.size() == 2);
    const StudyPoint &off = byEwa(judged, "off"), &ewa = byEwa(judged, "auto");
    CHECK(off.truthFilter == 0.0);  // point-sampled frames, point-sampled truth
    CHECK(ewa.truthFilter == Quality::kEwaDefaultSigma);
    o.truth = Truth::Point;
    const StudyResult point = runStudy(v, base, o);
    REQUIRE(point.points.size() == 2);
    CHECK(byEwa(point, "auto").truthFilter == 0.0);
    CHECK(byEwa(point, "off").rmse == off.rmse);
    // The filtered frames are far closer to the filtered truth than to the point-sampled one.
    INFO("against filtered " << ewa.rmse << ", against point " << byEwa(point, "auto").rmse);
    CHECK(ewa.rmse < 0.1 * byEwa(point, "auto").rmse);
}
