// End-to-end tests of `splat render`, `rotate`, `bench` and `compare`: outputs exist and
// hold the numbers the library computes; bad input gives one line, a non-zero status and
// no output file.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "cli_util.h"
#include "splat/image_io.h"
#include "splat/render.h"
#include "splat/synthetic.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {
void requireOneLineError(const RunResult& r, const std::string& text) {
    INFO("stderr: " << r.err);
    CHECK(r.status != 0);
    REQUIRE(r.errLines().size() == 1);
    CHECK(r.errLines()[0].rfind("splat: error:", 0) == 0);
    CHECK(r.err.find(text) != std::string::npos);
}
}  // namespace

TEST_CASE("render writes an EXR equal to the library's image", "[cli]") {
    const fs::path dir = testTmpDir("cli_render");
    const std::string out = (dir / "x.exr").string();
    const RunResult r = runSplat({"render", "synthetic:sphere:24", "--mode", "xray", "--size",
                                  "32x32", "--renderer", "sheet", "--azimuth", "20", "-o", out});
    INFO(r.err);
    REQUIRE(r.status == 0);
    const Image file = readImage(out);
    RenderSettings s;
    s.renderer = RendererKind::Sheet;
    s.mode = RenderMode::Xray;
    s.camera.width = s.camera.height = 32;
    s.camera.azimuthDeg = 20;
    const Image lib = render(makeSynthetic("sphere", 24), s);
    REQUIRE(file.width == 32);
    for (std::size_t n = 0; n < lib.pixels.size(); ++n)
        REQUIRE(file.pixels[n].r == lib.pixels[n].r);
}

TEST_CASE("a scene file sets options and flags override it", "[cli]") {
    const fs::path dir = testTmpDir("cli_scene");
    std::ofstream(dir / "scene.json") << R"({"renderer": "sheet", "slab": 0.5, "size": "24x16",
                                              "mode": "mip", "azimuth": 10})";
    const std::string out = (dir / "m.exr").string();
    const RunResult r = runSplat({"render", "synthetic:blob:16", "--scene",
                                  (dir / "scene.json").string(), "--size", "20x12", "-o", out});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("sheet mip") != std::string::npos);
    const Image img = readImage(out);
    CHECK(img.width == 20);
    CHECK(img.height == 12);
    std::ofstream(dir / "bad.json") << R"({"renderer": "sheet", "slabb": 1})";
    requireOneLineError(runSplat({"render", "synthetic:blob:8", "--scene",
                                  (dir / "bad.json").string(), "-o", (dir / "b.png").string()}),
                        "unknown scene key 'slabb'");
    CHECK(!fs::exists(dir / "b.png"));
}

TEST_CASE("rotate writes every frame and an animated GIF", "[cli]") {
    const fs::path dir = testTmpDir("cli_rotate");
    const RunResult r = runSplat({"rotate", "synthetic:phantom:24", "--tf", "ct-soft", "--size",
                                  "24x24", "--frames", "5", "-o", (dir / "frames").string(),
                                  "--gif", (dir / "new" / "r.gif").string()});
    INFO(r.err);
    REQUIRE(r.status == 0);
    for (int f = 0; f < 5; ++f)
        CHECK(fs::exists(dir / "frames" / ("frame_000" + std::to_string(f) + ".png")));
    REQUIRE(fs::exists(dir / "new" / "r.gif"));  // the GIF's folder is created like the frames'
    CHECK(fs::file_size(dir / "new" / "r.gif") > 200);
    requireOneLineError(
        runSplat({"rotate", "synthetic:blob:8", "--frames", "0", "-o", (dir / "z").string()}),
        "--frames");
}

TEST_CASE("bench writes JSON with a run per thread count", "[cli]") {
    const fs::path dir = testTmpDir("cli_bench");
    const std::string json = (dir / "b.json").string();
    const RunResult r = runSplat({"bench", "synthetic:blob:16", "--size", "32x32", "--repeats", "2",
                                  "--thread-list", "1,2", "--json", json});
    INFO(r.err);
    REQUIRE(r.status == 0);
    const std::string text = readTextFile(json);
    CHECK(text.find("\"median_ms\"") != std::string::npos);
    CHECK(text.find("\"threads\": 2") != std::string::npos);
}

TEST_CASE("render refuses bad options and outputs with one line and no file", "[cli]") {
    const fs::path dir = testTmpDir("cli_bad");
    const std::string out = (dir / "o.png").string();
    struct Bad {
        std::vector<std::string> args;
        std::string text;
    };
    const Bad cases[] = {
        {{"--renderer", "magic"}, "unknown renderer 'magic'"},
        {{"--bit-depth", "12"}, "--bit-depth"},
        {{"--slab", "0", "--renderer", "sheet"}, "slab thickness"},
        {{"--size", "0x10"}, "--size"},
        {{"--size", "banana"}, "--size"},
        {{"--size", "30000x30000"}, "Mpixels"},
        {{"--tf", "no-such-preset"}, "unknown transfer function preset"},
        {{"--tf", (dir / "missing.json").string()}, "cannot open transfer function file"},
        {{"--background", "1,2"}, "--background"},
        {{"--kernel", "sinc"}, "sinc"},
        {{"--early-termination", "1.5"}, "early termination"},
        {{"--projection", "fisheye"}, "unknown projection"},
    };
    for (const Bad& b : cases) {
        std::vector<std::string> args{"render", "synthetic:blob:8", "-o", out};
        args.insert(args.end(), b.args.begin(), b.args.end());
        INFO(b.text);
        requireOneLineError(runSplat(args), b.text);
        CHECK(!fs::exists(out));
    }
    requireOneLineError(runSplat({"render", "synthetic:blob:8", "-o", (dir / "x.bmpx").string()}),
                        "unsupported image type");
    requireOneLineError(
        runSplat({"render", "synthetic:blob:8", "-o", (dir / "nope" / "x.png").string()}),
        "does not exist");
    // Nothing but the scratch files of earlier cases is left in the folder.
    for (const auto& e : fs::directory_iterator(dir))
        CHECK(e.path().filename().string().find(".tmp") == std::string::npos);
}

TEST_CASE("compare reports zero error for identical images and a heat map", "[cli]") {
    const fs::path dir = testTmpDir("cli_compare");
    const std::string a = (dir / "a.exr").string();
    REQUIRE(runSplat({"render", "synthetic:blob:12", "--size", "16x16", "-o", a}).status == 0);
    const RunResult r = runSplat({"compare", a, a, "--heatmap", (dir / "h.png").string()});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("rmse       0") != std::string::npos);
    CHECK(fs::exists(dir / "h.png"));
}
