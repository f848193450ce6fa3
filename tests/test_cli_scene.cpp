// Scene files (docs/command-line.md "Scene files"): --write-scene writes the scene that reproduces
// an image byte for byte; relative paths are relative to the scene's folder; typed values and
// the old string forms; every malformed case names its key and the file (exit status 2);
// the metadata of written images; normalized and absolute iso levels.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "splat/image_io.h"

using namespace splat::test;
namespace fs = std::filesystem;

namespace {

std::string attribute(const fs::path& file, const std::string& key) {
    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    const std::string v = in->spec().get_string_attribute(key);
    in->close();
    return v;
}

bool samePixels(const fs::path& a, const fs::path& b) {
    const splat::Image x = splat::readImage(a.string()), y = splat::readImage(b.string());
    return x.width == y.width && x.height == y.height &&
           std::equal(x.pixels.begin(), x.pixels.end(), y.pixels.begin());
}

/// A 8x8x8 uint8 ramp 0..200 along x (min 0, max 200).
fs::path writeRamp(const fs::path& dir) {
    std::vector<unsigned char> v(512);
    for (int k = 0; k < 8; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i) v[(k * 8 + j) * 8 + i] = (unsigned char)(i * 200 / 7);
    const fs::path p = dir / "ramp.raw";
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(v.data()), 512);
    return p;
}

}  // namespace

TEST_CASE("write-scene: the scene written that reproduces the image byte for byte",
          "[cli][scene]") {
    const fs::path dir = testTmpDir("scene_reproduce");
    for (const char* ext : {".png", ".exr", ".tif"}) {
        const fs::path out = dir / (std::string("a") + ext), scene = dir / "s.json";
        const RunResult r = runSplat({"render",        "synthetic:phantom:16",
                                      "--tf",          "ct-soft",
                                      "--size",        "32x24",
                                      "--azimuth",     "30.1",
                                      "--elevation",   "-12.25",
                                      "--renderer",    "sheet",
                                      "--slab",        "0.37",
                                      "--shade",       "--clip-plane",
                                      "0,0,0,0,0.3,1", "--background",
                                      "0.1,0.2,0.3,1", "--kernel",
                                      "bspline",       "-o",
                                      out.string(),    "--write-scene",
                                      scene.string()});
        INFO(r.err);
        REQUIRE(r.status == 0);
        const std::string first = readTextFile(out);
        fs::remove(out);
        // The scene alone writes the same file again.
        const RunResult again = runSplat({"render", "--scene", scene.string()});
        INFO(again.err);
        REQUIRE(again.status == 0);
        CHECK(again.err.empty());
        CHECK(readTextFile(out) == first);
        // Its values are typed: numbers, arrays, booleans; the volume grouped.
        const nlohmann::json j = nlohmann::json::parse(readTextFile(scene));
        CHECK(j["command"] == "render");
        CHECK(j["volume"]["path"] == "synthetic:phantom:16");
        CHECK(j["azimuth"] == 30.1);
        CHECK(j["size"] == nlohmann::json::array({32, 24}));
        CHECK(j["shade"] == true);
        CHECK(j["clip-plane"][0].size() == 6);
        CHECK(j["output"] == out.string());
    }
}

TEST_CASE("images carry the command, the scene and the version as metadata", "[cli][scene]") {
    const fs::path dir = testTmpDir("scene_metadata");
    const fs::path scene = dir / "s.json";
    for (const char* ext : {".png", ".exr"}) {
        const fs::path out = dir / (std::string("m") + ext);
        REQUIRE(runSplat({"render", "synthetic:blob:8", "--size", "16x16", "--mode", "mip", "-o",
                          out.string(), "--write-scene", scene.string()})
                    .status == 0);
        CHECK(attribute(out, "Software").rfind("splat ", 0) == 0);
        CHECK(
            attribute(out, "splat:command").rfind("splat render synthetic:blob:8 --mode mip", 0) ==
            0);
        const nlohmann::json inFile = nlohmann::json::parse(attribute(out, "splat:scene"));
        CHECK(inFile == nlohmann::json::parse(readTextFile(scene)));
    }
    // TIFF keeps only its own tags: the entries are lines of its ImageDescription.
    const fs::path tif = dir / "m.tif";
    REQUIRE(
        runSplat({"render", "synthetic:blob:8", "--size", "16x16", "-o", tif.string()}).status ==
        0);
    CHECK(attribute(tif, "ImageDescription").find("splat:scene: {\"command\":\"render\"") !=
          std::string::npos);
}

TEST_CASE("a scene's relative paths are relative to its folder, not the working folder",
          "[cli][scene]") {
    const fs::path dir = testTmpDir("scene_relative");
    writeRamp(dir);
    std::ofstream(dir / "tf.json")
        << R"({"domain": "normalized", "points": [[0, 0, 0, 0, 0], [1, 1, 0.5, 0.2, 0.8]]})";
    std::ofstream(dir / "scene.json") << R"({
        "volume": {"path": "ramp.raw", "dims": [8, 8, 8], "type": "uint8",
                   "spacing": [1, 1, 2]},
        "tf": "tf.json", "size": [20, 16], "azimuth": 45, "output": "out.png"})";
    REQUIRE(fs::current_path() != dir);
    const RunResult r = runSplat({"render", "--scene", (dir / "scene.json").string()});
    INFO(r.err);
    REQUIRE(r.status == 0);
    REQUIRE(fs::exists(dir / "out.png"));
    // The same picture from absolute flags.
    const RunResult flags =
        runSplat({"render", (dir / "ramp.raw").string(), "--dims", "8x8x8", "--type", "uint8",
                  "--spacing", "1,1,2", "--tf", (dir / "tf.json").string(), "--size", "20x16",
                  "--azimuth", "45", "-o", (dir / "flags.png").string()});
    REQUIRE(flags.status == 0);
    CHECK(samePixels(dir / "out.png", dir / "flags.png"));
    // An inline transfer function gives the same picture as the file.
    std::ofstream(dir / "inline.json") << R"({
        "volume": {"path": "ramp.raw", "dims": "8x8x8", "type": "uint8", "spacing": "1,1,2"},
        "tf": {"domain": "normalized", "points": [[0, 0, 0, 0, 0], [1, 1, 0.5, 0.2, 0.8]]},
        "size": "20x16", "azimuth": "45", "output": "inline.png"})";
    const RunResult in = runSplat({"render", "--scene", (dir / "inline.json").string()});
    INFO(in.err);
    REQUIRE(in.status == 0);
    CHECK(samePixels(dir / "inline.png", dir / "flags.png"));
    // A flag given on the command line overrides its key (here the output).
    REQUIRE(runSplat({"render", "--scene", (dir / "inline.json").string(), "-o",
                      (dir / "over.png").string()})
                .status == 0);
    CHECK(fs::exists(dir / "over.png"));
}

TEST_CASE("each malformed scene names its key and the file, exit status 2", "[cli][scene]") {
    const fs::path dir = testTmpDir("scene_bad");
    struct Bad {
        std::string json, key;
    };
    const Bad cases[] = {
        {R"({"slabb": 1})", "'slabb'"},
        {R"({"size": {"w": 2}})", "\"size\""},
        {R"({"size": true})", "\"size\""},
        {R"({"shade": 1})", "\"shade\""},
        {R"({"azimuth": [1, 2]})", "\"azimuth\""},
        {R"({"azimuth": "east"})", "\"azimuth\""},
        {R"({"threads": 1e10})", "\"threads\""},
        {R"({"threads": 3.7})", "\"threads\""},
        {R"({"threads": 4294967304})", "\"threads\""},
        {R"({"tile-size": -3000000000})", "\"tile-size\""},
        {R"({"volume": {"path": "synthetic:blob:8", "dimz": [1, 2, 3]}})", "'volume.dimz'"},
        {R"({"header-bytes": -1})", "\"header-bytes\""},
        {R"({"clip-plane": true})", "\"clip-plane\""},
        {R"({"tf": {"points": 3}})", "\"tf\""},
        {R"({"command": 7})", "\"command\""},
        {R"([1, 2])", "JSON object"},
        {R"({"size": )", "not valid JSON"},
    };
    int n = 0;
    for (const Bad& b : cases) {
        const fs::path scene = dir / ("bad" + std::to_string(n++) + ".json");
        std::ofstream(scene) << b.json;
        const RunResult r = runSplat({"render", "synthetic:blob:8", "--scene", scene.string(), "-o",
                                      (dir / "o.png").string()});
        INFO(b.json << "\n" << r.err);
        CHECK(r.status == 2);
        REQUIRE(r.errLines().size() == 1);
        CHECK(r.err.find(scene.string()) != std::string::npos);
        CHECK(r.err.find(b.key) != std::string::npos);
        CHECK(!fs::exists(dir / "o.png"));
    }
    // A value that a flag would refuse is refused the same way from a scene.
    std::ofstream(dir / "tile.json") << R"({"tile-size": 1})";
    CHECK(runSplat({"render", "synthetic:blob:8", "--scene", (dir / "tile.json").string(), "-o",
                    (dir / "o.png").string()})
              .status == 2);
    // A missing scene file is a failure of the work.
    CHECK(runSplat({"render", "--scene", (dir / "none.json").string()}).status == 1);
}

TEST_CASE("keys of another command are named in one warning line", "[cli][scene]") {
    const fs::path dir = testTmpDir("scene_other");
    const fs::path scene = dir / "rot.json";
    REQUIRE(runSplat({"rotate", "synthetic:blob:8", "--size", "8x8", "--frames", "2", "-q", "-o",
                      (dir / "f").string(), "--write-scene", scene.string()})
                .status == 0);
    const RunResult r =
        runSplat({"render", "--scene", scene.string(), "-o", (dir / "one.png").string()});
    INFO(r.err);
    CHECK(r.status == 0);
    REQUIRE(r.errLines().size() == 1);
    CHECK(r.err.find("splat: warning:") == 0);
    CHECK(r.err.find("frames") != std::string::npos);
    // rotate reproduces its own frames from the scene.
    const fs::path frame = dir / "f" / "frame_0001.png";
    const splat::Image before = splat::readImage(frame.string());
    fs::remove(frame);
    const RunResult again = runSplat({"rotate", "--scene", scene.string(), "--resume"});
    INFO(again.err);
    REQUIRE(again.status == 0);
    CHECK(again.out.find("wrote 1 frames") != std::string::npos);
    CHECK(splat::readImage(frame.string()).pixels == before.pixels);
}

TEST_CASE("iso levels: absolute levels and fractions of the range ending in n", "[cli][scene]") {
    const fs::path dir = testTmpDir("scene_iso");
    const fs::path ramp = writeRamp(dir);
    auto render = [&](const std::string& level, const std::string& name) {
        std::vector<std::string> args{"render",    ramp.string(),
                                      "--dims",    "8x8x8",
                                      "--type",    "uint8",
                                      "--mode",    "iso",
                                      "--size",    "24x24",
                                      "--azimuth", "90",
                                      "--background-value", "0",  // the ramp fills its faces
                                      "-o",        (dir / name).string()};
        if (!level.empty()) {
            args.push_back("--iso-level");
            args.push_back(level);
        }
        const RunResult r = runSplat(args);
        INFO(r.err);
        REQUIRE(r.status == 0);
        return dir / name;
    };
    // The ramp spans [0, 200]: 0.4n is 80, and the default 0.5n is 100.
    CHECK(samePixels(render("0.4n", "n.exr"), render("80", "a.exr")));
    CHECK(samePixels(render("", "d.exr"), render("100", "h.exr")));
    CHECK(!samePixels(render("0.4n", "n2.exr"), render("0.4", "abs.exr")));
}

TEST_CASE("a scene file as VOLUME, and a Gaussian scene as a scene's input", "[cli][scene]") {
    const fs::path dir = testTmpDir("scene_gaussians");
    const fs::path a = dir / "a.png", b = dir / "b.png", c = dir / "c.png";
    const fs::path scene = dir / "g.json";
    REQUIRE(runSplat({"render", "gaussians:pop", "--size", "24x16", "--azimuth", "20", "-o",
                      a.string(), "--write-scene", scene.string()})
                .status == 0);
    std::ifstream in(scene);
    const nlohmann::json j = nlohmann::json::parse(in);
    // A generated input names no file: written as given, not made absolute.
    CHECK(j["volume"]["path"] == "gaussians:pop");
    const RunResult r = runSplat({"render", "--scene", scene.string(), "-o", b.string()});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(samePixels(a, b));
    // `splat render scene.json` is `splat render --scene scene.json`.
    const RunResult s = runSplat({"render", scene.string(), "-o", c.string()});
    INFO(s.err);
    REQUIRE(s.status == 0);
    CHECK(samePixels(a, c));
    // A scene without "volume" still says what is missing.
    const fs::path empty = dir / "empty.json";
    std::ofstream(empty) << R"({"command": "render", "size": "8x8"})";
    const RunResult e = runSplat({"render", empty.string(), "-o", c.string()});
    CHECK(e.status == 2);
    CHECK(e.err.find("needs VOLUME") != std::string::npos);
}

TEST_CASE("a Gaussian scene's --slab and --ref-tolerance reach its renderers, from flags and "
          "scenes", "[cli][scene]") {
    const fs::path dir = testTmpDir("scene_gaussian_slab");
    const fs::path thin = dir / "thin.exr", thick = dir / "thick.exr", fromScene = dir / "s.exr";
    const fs::path scene = dir / "thin.json";
    const std::vector<std::string> common = {"gaussians:pop", "--renderer", "sheet", "--size",
                                             "32x24", "--azimuth", "20"};
    auto render = [&](const fs::path& out, std::vector<std::string> extra) {
        std::vector<std::string> a = {"render"};
        a.insert(a.end(), common.begin(), common.end());
        a.insert(a.end(), extra.begin(), extra.end());
        a.insert(a.end(), {"-o", out.string()});
        return runSplat(a);
    };
    REQUIRE(render(thin, {"--slab", "0.05", "--write-scene", scene.string()}).status == 0);
    REQUIRE(render(thick, {"--slab", "2"}).status == 0);
    // Slabs of 0.05 and 2 (the sheets' error falls as the slab thins): different images.
    const splat::Image a = splat::readImage(thin.string()), b = splat::readImage(thick.string());
    REQUIRE(a.pixels.size() == b.pixels.size());
    float largest = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 4; ++c)
            largest = std::max(largest, std::abs(a.pixels[i][c] - b.pixels[i][c]));
    CHECK(largest > 1e-3f);
    const RunResult r = runSplat({"render", "--scene", scene.string(), "-o", fromScene.string()});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(samePixels(thin, fromScene));
}
