// The library beyond one frame: progress totals known up front for
// sequences, popping and studies, cancel reaching the frame in flight; the popping analyzer
// over any camera path; one end-point convention; honest exact-path fallbacks.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "splat/image_io.h"
#include "splat/popping.h"
#include "splat/render.h"
#include "splat/sequence.h"
#include "splat/study.h"
#include "splat/synthetic.h"

using namespace splat;
namespace fs = std::filesystem;

namespace {

RenderSettings cubeSettings() {
    RenderSettings s;
    s.transfer.normalized = true;
    s.transfer.points = {{0.0f, glm::vec4(0, 0, 0, 0)},
                         {0.3f, glm::vec4(1, 0.1f, 0.1f, 0.4f)},
                         {0.6f, glm::vec4(0.1f, 1, 0.1f, 0.7f)},
                         {1.0f, glm::vec4(0.1f, 0.2f, 1, 0.9f)}};
    s.classification = Classification::Post;
    s.camera.width = s.camera.height = 48;
    s.threads = 2;
    return s;
}

// Every (done, total) a progress callback saw.
struct ProgressLog {
    std::vector<std::pair<std::size_t, std::size_t>> calls;
    ProgressFn fn() {
        return [this](std::size_t d, std::size_t t, const std::string&) {
            calls.emplace_back(d, t);
            return true;
        };
    }
    std::size_t distinctTotals() const {
        std::vector<std::size_t> t;
        for (const auto& c : calls)
            if (t.empty() || t.back() != c.second) t.push_back(c.second);
        return t.size();
    }
};

}  // namespace

TEST_CASE("end points: inclusive everywhere (Sweep, CameraPath::turn)", "[paths]") {
    CameraParams c;
    const CameraPath p = CameraPath::turn(c, CameraPath::Angle::Azimuth, 0, 90, 4);
    REQUIRE(p.views.size() == 4);
    CHECK(p.views[0].azimuthDeg == 0);
    CHECK(p.views[1].azimuthDeg == 30);
    CHECK(p.views[3].azimuthDeg == 90);  // before: closed turns ended at 67.5
    const CameraPath one = CameraPath::turn(c, CameraPath::Angle::Elevation, -30, 30, 1);
    CHECK(one.views.at(0).elevationDeg == -30);
    Sweep s;
    s.from = 40;
    s.to = 50;
    s.step = 5;
    CHECK(s.angles() == std::vector<double>{40, 45, 50});
}

TEST_CASE("end points: splat rotate's --to is the last frame; the default loops", "[paths][cli]") {
    const fs::path dir = test::testTmpDir("rotate_endpoints");
    fs::remove_all(dir);
    auto run = [&](const std::string& sub, std::vector<std::string> extra) {
        std::vector<std::string> a = {
            "rotate", "synthetic:blob:16",  "--size", "24x24",    "--mode", "mip",
            "-o",     (dir / sub).string(), "-q",     "--format", "exr"};
        a.insert(a.end(), extra.begin(), extra.end());
        REQUIRE(test::runSplat(a).status == 0);
    };
    auto frameAt = [&](const std::string& sub, int n) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%04d.exr", n);
        return readImage((dir / sub / name).string());
    };
    auto renderAt = [&](const std::string& sub, double azimuth) {
        const fs::path out = dir / (sub + ".exr");
        REQUIRE(test::runSplat({"render", "synthetic:blob:16", "--size", "24x24", "--mode", "mip",
                                "--azimuth", std::to_string(azimuth), "-o", out.string()})
                    .status == 0);
        return readImage(out.string());
    };
    run("explicit", {"--frames", "4", "--from", "0", "--to", "90"});
    CHECK(frameAt("explicit", 3).pixels == renderAt("at90", 90).pixels);
    run("loop", {"--frames", "4"});
    CHECK(frameAt("loop", 3).pixels == renderAt("at270", 270).pixels);
}

TEST_CASE("popping over a camera path: the sweep's views as a path give the sweep's analysis",
          "[paths][popping]") {
    const Scene scene(makeSynthetic("cube", 24), cubeSettings());
    Sweep sweep;
    sweep.from = 40;
    sweep.to = 50;
    sweep.step = 0.5;
    sweep.base = scene.settings().camera;
    PoppingOptions o;
    o.refine = 8;
    o.flip = false;
    const PoppingResult bySweep = analyzePopping(scene, sweep, o);
    std::vector<CameraParams> views;
    for (double a : sweep.angles()) views.push_back(sweep.camera(a));
    const PoppingResult byPath = analyzePopping(scene, views, o);
    REQUIRE(byPath.pathViews == 21);
    REQUIRE(byPath.angles.size() == 21);
    CHECK(byPath.angles[20] == 20.0);
    // The same frames: the same measures, threshold and events.
    for (std::size_t k = 0; k < bySweep.series.size(); ++k) {
        CHECK(byPath.series[k].T == bySweep.series[k].T);
        CHECK(byPath.series[k].J == bySweep.series[k].J);
        CHECK(byPath.series[k].threshold == bySweep.series[k].threshold);
    }
    REQUIRE(byPath.predictedSwitches.size() == 1);
    CHECK(40 + 0.5 * byPath.predictedSwitches[0] ==
          Approx(bySweep.predictedSwitches[0]).margin(1e-6));
    REQUIRE(byPath.events.size() == bySweep.events.size());
    REQUIRE(!byPath.events.empty());
    for (std::size_t e = 0; e < byPath.events.size(); ++e) {
        const PoppingEvent &p = byPath.events[e], &s = bySweep.events[e];
        CHECK(40 + 0.5 * p.angleFrom == s.angleFrom);
        // Refinement interpolates the camera: the same bisection in path units.
        CHECK(40 + 0.5 * p.refinedAngle == Approx(s.refinedAngle).margin(1e-9));
        CHECK(p.refinedSlope == Approx(s.refinedSlope).margin(0.05));
        CHECK(p.refinement.size() == s.refinement.size());
    }
    // The report says what the positions are.
    const fs::path dir = test::testTmpDir("popping_path_report");
    fs::remove_all(dir);
    writePoppingReport(byPath, dir.string(), "test");
    std::ifstream in(dir / "summary.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    CHECK(j["sweep"]["angle"] == "path");
    CHECK(j["sweep"]["views"] == 21);
}

TEST_CASE("popping over a camera path: free cameras, interpolation, refusals", "[paths][popping]") {
    const Scene scene(makeSynthetic("blob", 16), [] {
        RenderSettings s;
        s.mode = RenderMode::Mip;
        s.camera.width = s.camera.height = 24;
        s.threads = 2;
        return s;
    }());
    const glm::dvec3 c = scene.volume().center();
    std::vector<CameraParams> views;
    for (int n = 0; n < 5; ++n) {
        CameraParams v = scene.settings().camera;
        v.lookAtSet = true;
        v.lookAt = c + glm::dvec3(0.3 * n, 0, 0);  // off-centre, moving
        v.eye = c + glm::dvec3(40 * std::sin(0.2 * n), -40 * std::cos(0.2 * n), 5);
        views.push_back(v);
    }
    PoppingOptions o;
    o.refine = 2;
    o.flip = false;
    o.renderers = {RendererKind::Sheet, RendererKind::Reference};
    const PoppingResult r = analyzePopping(scene, views, o);
    CHECK(r.angles.size() == 5);
    CHECK(r.series[0].T.size() == 4);
    // interpolateCamera: linear in every number, exact at the ends.
    const CameraParams mid = interpolateCamera(views[1], views[2], 0.25);
    CHECK(mid.eye.x == Approx(views[1].eye.x + 0.25 * (views[2].eye.x - views[1].eye.x)));
    CHECK(mid.lookAt.x == Approx(c.x + 0.3 * 1.25));
    CHECK(interpolateCamera(views[1], views[2], 1.0).eye == views[2].eye);
    CameraParams orbit = scene.settings().camera;
    CHECK_THROWS_WITH(interpolateCamera(views[0], orbit, 0.5), Catch::Contains("free"));
    orbit.width = 30;
    std::vector<CameraParams> bad = {scene.settings().camera, scene.settings().camera, orbit};
    CHECK_THROWS_WITH(analyzePopping(scene, bad, o), Catch::Contains("image sizes"));
    CHECK_THROWS_WITH(analyzePopping(scene, std::vector<CameraParams>(2), o),
                      Catch::Contains("at least 3 views"));
}

TEST_CASE("progress: popping's total is fixed for the sweep and grows once, for refinement",
          "[paths][popping][progress]") {
    const Scene scene(makeSynthetic("cube", 24), cubeSettings());
    Sweep sweep;
    sweep.from = 40;
    sweep.to = 50;
    sweep.step = 1;
    sweep.base = scene.settings().camera;
    PoppingOptions o;
    o.refine = 3;
    o.flip = false;
    ProgressLog log;
    o.progress = log.fn();
    const PoppingResult r = analyzePopping(scene, sweep, o);
    REQUIRE(!r.events.empty());
    const std::size_t kinds = 3, sweepFrames = 11 * kinds;
    const std::size_t all = sweepFrames + r.events.size() * (o.refine + 2) * kinds;
    REQUIRE(!log.calls.empty());
    // Before: total == done at every call (109/109, 110/110).
    CHECK(log.calls.front().second == sweepFrames);
    CHECK(log.calls.back() == std::make_pair(all, all));
    CHECK(log.distinctTotals() == 2);
    std::size_t lastDone = 0;
    for (const auto& [d, t] : log.calls) {
        CHECK(d <= t);
        CHECK(d >= lastDone);
        lastDone = d;
    }
}

TEST_CASE("progress: renderSequence's total is known up front; cancel stops the frame in flight",
          "[paths][progress]") {
    RenderSettings s;
    s.transfer = TransferFunction::preset("ct-soft");
    s.camera.width = s.camera.height = 320;  // one frame at a time, many tiles
    s.quality.tileSize = 16;
    s.threads = 2;
    const Scene scene(makeSynthetic("phantom", 48), s);
    const CameraPath path = CameraPath::turn(s.camera, CameraPath::Angle::Azimuth, 0, 30, 4);
    ProgressLog log;
    SequenceOptions so;
    so.progress = log.fn();
    std::size_t frames = 0;
    renderSequence(scene, {RendererKind::Sheet, RendererKind::Axis}, path, so,
                   [&](SequenceFrame&&) { ++frames; });
    CHECK(frames == 4);
    CHECK(log.distinctTotals() == 1);
    CHECK(log.calls.front().second == 8);
    CHECK(log.calls.back().first == 8);
    CHECK(log.calls.size() > 8);  // polled inside the frames too
    // Cancel at the first poll inside the first frame: before, the frame ran to its end.
    std::size_t polls = 0;
    std::string seen;
    so.progress = [&](std::size_t, std::size_t, const std::string& what) {
        ++polls;
        seen = what;
        return false;
    };
    frames = 0;
    CHECK_THROWS_AS(renderSequence(scene, {RendererKind::Reference}, path, so,
                                   [&](SequenceFrame&&) { ++frames; }),
                    Cancelled);
    CHECK(frames == 0);
    CHECK(polls == 1);
    CHECK_THAT(seen, Catch::Contains("rows"));
}

TEST_CASE("fallbacks: a splatter's exact pixels are counted, explained and reported",
          "[paths][fallback]") {
    const Volume v = makeSynthetic("blob", 20);
    const Camera fit(CameraParams{}, v);
    RenderSettings s;
    s.mode = RenderMode::Xray;
    s.camera.width = s.camera.height = 24;
    s.camera.projection = Projection::Perspective;
    s.camera.fovDeg = 90;
    s.camera.distance = 0.3 * fit.boundingRadius;  // the eye inside the volume
    s.threads = 2;
    const Scene scene(v, s);
    for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet}) {
        s.renderer = r;
        RenderStats st;
        scene.render(s, &st);
        CHECK(st.exactPixels == 24u * 24u);
        CHECK_THAT(st.exactReason, Catch::Contains("reference ray caster"));
    }
    s.camera.distance = 0;  // outside: no fallback, no reason
    RenderStats st;
    scene.render(s, &st);
    CHECK(st.exactPixels == 0);
    CHECK(st.exactReason.empty());

    // The popping report lists such views; the CLI warns.
    std::vector<CameraParams> views;
    for (double d : {0.0, 0.0, 0.3 * fit.boundingRadius, 0.0}) {
        CameraParams c = s.camera;
        c.distance = d;
        views.push_back(c);
    }
    PoppingOptions o;
    o.flip = false;
    o.refine = 0;
    const PoppingResult r = analyzePopping(scene, views, o);
    const RendererSeries* axis = r.find(RendererKind::Axis);
    REQUIRE(axis);
    CHECK(axis->exactPixels == std::vector<std::size_t>{0, 0, 576, 0});
    CHECK(r.find(RendererKind::Reference)->exactPixels == std::vector<std::size_t>(4, 0));
    const fs::path dir = test::testTmpDir("popping_exact_report");
    fs::remove_all(dir);
    writePoppingReport(r, dir.string(), "test");
    std::ifstream in(dir / "summary.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    CHECK(j["renderers"]["axis"]["exact_views"] == nlohmann::json::array({2.0}));
    CHECK(j["renderers"]["reference"]["exact_views"].empty());

    const test::RunResult cli = test::runSplat(
        {"render", "synthetic:blob:20", "--mode", "xray", "--size", "24x24", "--projection",
         "perspective", "--fov", "90", "--distance", std::to_string(0.3 * fit.boundingRadius),
         "--renderer", "sheet", "-o", (dir / "near.exr").string()});
    CHECK(cli.status == 0);
    CHECK_THAT(cli.err, Catch::Contains("576 of 576 pixels handed to the exact path"));
}

TEST_CASE("progress: a study's total is fixed; cancel reaches inside its frames",
          "[paths][progress][study]") {
    auto volume = std::make_shared<const Volume>(makeSynthetic("blob", 16));
    RenderSettings base;
    base.camera.width = base.camera.height = 64;
    base.threads = 2;
    base.transfer = TransferFunction::preset("gray-ramp");
    StudyOptions o;
    o.sweeps = {{"renderer", {"axis", "sheet"}}};
    o.repeats = 2;
    o.warmup = 0;
    ProgressLog log;
    o.progress = log.fn();
    runStudy(volume, base, o);
    CHECK(log.distinctTotals() == 1);
    CHECK(log.calls.back().first == log.calls.back().second);
    std::size_t polls = 0;
    std::size_t doneAtCancel = 99;
    o.progress = [&](std::size_t d, std::size_t, const std::string&) {
        doneAtCancel = d;
        return ++polls < 2;  // cancel at the second poll, inside the first frame
    };
    CHECK_THROWS_AS(runStudy(volume, base, o), Cancelled);
    CHECK(polls == 2);
    CHECK(doneAtCancel == 0);  // before: only between frames, at done 1
}

TEST_CASE("splat popping --path analyses a camera path; --path refuses sweep options",
          "[paths][cli]") {
    const fs::path dir = test::testTmpDir("popping_cli_path");
    fs::remove_all(dir);
    fs::create_directories(dir);
    {
        std::ofstream path(dir / "path.json");
        path << R"({"keys": [{"azimuth": 40, "elevation": 0}, {"azimuth": 50, "elevation": 5}]})";
    }
    const std::vector<std::string> base = {"popping",     "synthetic:cube:16",
                                           "--size",      "24x24",
                                           "--renderers", "axis,sheet",
                                           "--no-flip",   "--refine",
                                           "1",           "-q",
                                           "--path",      (dir / "path.json").string()};
    auto args = base;
    for (const char* a : {"--frames", "11", "--report"}) args.push_back(a);
    args.push_back((dir / "report").string());
    const test::RunResult r = test::runSplat(args);
    REQUIRE(r.status == 0);
    std::ifstream in(dir / "report" / "summary.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    CHECK(j["sweep"]["angle"] == "path");
    CHECK(j["sweep"]["views"] == 11);
    args = base;
    for (const char* a : {"--from", "10", "--report"}) args.push_back(a);
    args.push_back((dir / "bad").string());
    const test::RunResult bad = test::runSplat(args);
    CHECK(bad.status == 2);
    CHECK_THAT(bad.err, Catch::Contains("--from does not apply with --path"));
}
