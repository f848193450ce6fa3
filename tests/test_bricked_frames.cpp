// Bricked sequences without MPI (splat/bricks.h BrickedFrames): the bricks'
// Scenes built once and rendered view after view equal one-process frames, and
// `splat rotate --bricks K` writes the frames `splat rotate` writes (docs/parallel.md).
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "image_diff.h"
#include "splat/bricks.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/scene.h"
#include "splat/sequence.h"
#include "splat/volume_io.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

TEST_CASE("bricked frames: Scenes built once render every view as one process", "[bricks]") {
    const std::string spec = "synthetic:phantom:27";
    const Volume v = loadVolume(spec);
    bool alone = false;
    const Volume geometry = volumeGeometry(spec, {}, &alone);
    const auto load = [&](const Brick& b) { return loadVolumeBrick(spec, {}, b.loadLo, b.loadHi); };
    struct Case {
        RendererKind renderer;
        RenderMode mode;
        BrickComposite composite;
        double bound;  // of the peak
    };
    for (const Case c :
         {Case{RendererKind::Reference, RenderMode::Dvr, BrickComposite::Exact, 1e-5},
          Case{RendererKind::Reference, RenderMode::Mip, BrickComposite::Exact, 1e-5},
          Case{RendererKind::Axis, RenderMode::Dvr, BrickComposite::Exact, 1e-5},
          Case{RendererKind::Sheet, RenderMode::Dvr, BrickComposite::Exact, 1e-5},
          Case{RendererKind::Sheet, RenderMode::Dvr, BrickComposite::Fast, 0.05}}) {
        RenderSettings s;
        s.renderer = c.renderer;
        s.mode = c.mode;
        s.camera.width = 40;
        s.camera.height = 36;
        s.quality.earlyTermination = 0;  // a bricked frame integrates every brick
        s.quality.referenceTolerance = 1e-7;
        const Scene scene(std::make_shared<const Volume>(v), s);
        const CameraPath path = CameraPath::turn(s.camera, CameraPath::Angle::Azimuth, 10, 250, 4);
        for (int bricks : {3, 4}) {
            LocalBrickGroup group;
            BrickedFrames frames(geometry, load, s, bricks, group, c.composite);
            const BrickStats built = frames.stats();
            CHECK(built.rendered == bricks);
            for (const CameraParams& view : path.views) {
                RenderSettings sv = s;
                sv.camera = view;
                const Image one = scene.render(sv);
                const Image b = frames.render(view);
                INFO(toString(c.renderer) << " " << toString(c.mode) << " K " << bricks);
                CHECK(maxDiff(one, b) <= c.bound * peakOf(one));
                CHECK(peakOf(one) > 0.05f);
                // A frame of the kept Scenes is the frame of bricks loaded for it alone.
                BrickStats st;
                const Image fresh =
                    renderBricked(geometry, load, sv, bricks, group, &st, c.composite);
                CHECK(maxDiff(fresh, b) == 0.0f);
            }
            // Loaded and built once, however many views.
            CHECK(frames.stats().loadMs == built.loadMs);
            CHECK(frames.stats().sceneMs == built.sceneMs);
            CHECK(frames.stats().samplesLoaded == built.samplesLoaded);
        }
    }
}

TEST_CASE("bricked frames: a brick that fails to load is one error", "[bricks]") {
    bool alone = false;
    const Volume geometry = volumeGeometry("synthetic:phantom:16", {}, &alone);
    RenderSettings s;
    LocalBrickGroup group;
    CHECK_THROWS_WITH(BrickedFrames(
                          geometry,
                          [](const Brick& b) -> Volume {
                              if (b.lo.x > 0) throw Error("brick unreadable");
                              return loadVolumeBrick("synthetic:phantom:16", {}, b.loadLo,
                                                     b.loadHi);
                          },
                          s, 2, group),
                      Catch::Contains("brick unreadable"));
}

TEST_CASE("cli: rotate --bricks K writes the frames of rotate", "[bricks][cli]") {
    const fs::path dir = testTmpDir("rotate_bricks");
    fs::remove_all(dir);
    for (const std::string renderer : {"reference", "sheet"}) {
        auto args = [&](const std::string& out, const std::vector<std::string>& more) {
            std::vector<std::string> a = {"rotate",
                                          "synthetic:phantom:25",
                                          "--renderer",
                                          renderer,
                                          "--size",
                                          "36x32",
                                          "--frames",
                                          "3",
                                          "--format",
                                          "exr",
                                          "--early-termination",
                                          "0",
                                          "--ref-tolerance",
                                          "1e-7",
                                          "-q",
                                          "-o",
                                          (dir / (renderer + out)).string()};
            a.insert(a.end(), more.begin(), more.end());
            return a;
        };
        const RunResult one = runSplat(args("_one", {}));
        REQUIRE(one.status == 0);
        const RunResult b3 = runSplat(args("_b3", {"--bricks", "3"}));
        INFO(b3.err);
        REQUIRE(b3.status == 0);
        for (int f = 0; f < 3; ++f) {
            char name[32];
            std::snprintf(name, sizeof name, "frame_%04d.exr", f);
            const Image a = readImage((dir / (renderer + "_one") / name).string());
            const Image b = readImage((dir / (renderer + "_b3") / name).string());
            INFO(renderer << " frame " << f);
            CHECK(maxDiff(a, b) <= 1e-5 * peakOf(a));
        }
        // --resume with bricks renders only the missing frame.
        fs::remove(dir / (renderer + "_b3") / "frame_0001.exr");
        const RunResult r = runSplat(args("_b3", {"--bricks", "3", "--resume"}));
        REQUIRE(r.status == 0);
        CHECK(fs::exists(dir / (renderer + "_b3") / "frame_0001.exr"));
    }
    // Bad values are usage errors.
    CHECK(runSplat({"rotate", "synthetic:phantom:8", "--bricks", "-1", "-o", (dir / "x").string()})
              .status == 2);
    CHECK(runSplat({"rotate", "synthetic:phantom:8", "--bricks", "2", "--brick-composite", "no",
                    "-o", (dir / "x").string()})
              .status == 2);
}

TEST_CASE("cli: popping --bricks K finds the events of popping", "[bricks][cli]") {
    const fs::path dir = testTmpDir("popping_bricks");
    fs::remove_all(dir);
    // The axis-aligned splatter's sheet switch at 45 degrees, refined 3 levels.
    auto run = [&](int bricks) {
        const std::string out = (dir / "k").string() + std::to_string(bricks);
        const RunResult r = runSplat({"popping",
                                      "synthetic:phantom:24",
                                      "--size",
                                      "48x48",
                                      "--from",
                                      "40",
                                      "--to",
                                      "52",
                                      "--step",
                                      "1",
                                      "--refine",
                                      "3",
                                      "--early-termination",
                                      "0",
                                      "--no-flip",
                                      "-q",
                                      "--bricks",
                                      std::to_string(bricks),
                                      "--report",
                                      out});
        INFO(r.err);
        REQUIRE(r.status == 0);
        std::ifstream in(out + "/summary.json");
        return nlohmann::json::parse(in);
    };
    const nlohmann::json one = run(0);
    for (int k : {3, 5}) {
        const nlohmann::json b = run(k);
        for (const char* renderer : {"axis", "sheet", "reference"}) {
            const nlohmann::json &e1 = one["renderers"][renderer]["events"],
                                 &eb = b["renderers"][renderer]["events"];
            INFO(renderer << " K " << k);
            REQUIRE(e1.size() == eb.size());
            for (std::size_t i = 0; i < e1.size(); ++i) {
                for (const char* key : {"angle_from", "angle_to", "refined_width", "refined_angle",
                                        "sheet_axis_before", "sheet_axis_after",
                                        "sheet_sign_before", "sheet_sign_after", "predicted"})
                    CHECK(e1[i][key] == eb[i][key]);
                // The same classification: a discontinuity (|slope| < 0.25) or not.
                CHECK((std::abs(e1[i]["refined_slope"].get<double>()) < 0.25) ==
                      (std::abs(eb[i]["refined_slope"].get<double>()) < 0.25));
            }
        }
        CHECK(one["renderers"]["axis"]["events"].size() == 1);
        CHECK(one["predicted_switches"] == b["predicted_switches"]);
    }
    // K out of range: a usage error.
    CHECK(runSplat({"popping", "synthetic:phantom:8", "--bricks", "-1", "--report",
                    (dir / "x").string()})
              .status == 2);
}

// The reference's mip polishes every local maximum of its samples that could hold the peak,
// not only the largest sample's: a brick's segments start at its own face, so its samples
// fall elsewhere than one process's, and at 5 pixels of this view the largest sample lay on
// another hill than the peak (2.0e-4 of the peak apart before; see reference.cpp).
TEST_CASE("cli: the reference's mip in bricks equals one process within 1e-5 of the peak",
          "[bricks][cli]") {
    const fs::path dir = testTmpDir("mip_bricks");
    auto args = [&](const std::string& out, const std::string& bricks) {
        return std::vector<std::string>{"render",      "synthetic:phantom:96",
                                        "--renderer",  "reference",
                                        "--mode",      "mip",
                                        "--size",      "128x128",
                                        "--azimuth",   "33",
                                        "--elevation", "21",
                                        "--bricks",    bricks,
                                        "-o",          (dir / out).string()};
    };
    REQUIRE(runSplat(args("one.exr", "0")).status == 0);
    REQUIRE(runSplat(args("four.exr", "4")).status == 0);
    const Image one = readImage((dir / "one.exr").string());
    CHECK(maxDiff(one, readImage((dir / "four.exr").string())) <= 1e-5f * peakOf(one));
}
