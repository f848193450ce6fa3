// `splat rotate` through the sequence engine: frames, GIF, contact sheet, resume after an
// interruption, refusal of folders with foreign frames, camera paths.
#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "cli_util.h"
#include "splat/image_io.h"

using namespace splat::test;
namespace fs = std::filesystem;

namespace {
std::vector<std::string> rotateArgs(const fs::path& dir, int frames) {
    return {"rotate",   "synthetic:phantom:32", "--tf", "ct-soft",    "--size", "48x48",
            "--frames", std::to_string(frames), "-o",   dir.string(), "-q"};
}

int gifFrames(const fs::path& gif) {
    auto in = OIIO::ImageInput::open(gif.string());
    REQUIRE(in);
    int n = 0;
    while (in->seek_subimage(n, 0)) ++n;
    return n;
}

std::size_t countFiles(const fs::path& dir, const std::string& ext) {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir)) n += e.path().extension() == ext;
    return n;
}
}  // namespace

TEST_CASE("rotate: N frames decode, the GIF has N frames, the contact sheet tiles them",
          "[cli][rotate]") {
    const fs::path dir = testTmpDir("rotate_basic");
    fs::remove_all(dir);
    auto args = rotateArgs(dir / "frames", 6);
    for (const std::string& s : std::vector<std::string>{
             "--gif", (dir / "a.gif").string(), "--contact-sheet", (dir / "sheet.png").string()})
        args.push_back(s);
    const RunResult r = runSplat(args);
    REQUIRE(r.status == 0);
    REQUIRE(countFiles(dir / "frames", ".png") == 6);
    for (int f = 0; f < 6; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%04d.png", f);
        const splat::Image im = splat::readImage((dir / "frames" / name).string());
        CHECK(im.width == 48);
    }
    CHECK(gifFrames(dir / "a.gif") == 6);
    const splat::Image sheet = splat::readImage((dir / "sheet.png").string());
    CHECK(sheet.width == 3 * 48);  // 6 frames: 3 columns, 2 rows
    CHECK(sheet.height == 2 * 48);
}

TEST_CASE("rotate: --resume renders only the missing frames and matches a full run",
          "[cli][rotate]") {
    const fs::path dir = testTmpDir("rotate_resume");
    fs::remove_all(dir);
    auto full = rotateArgs(dir / "full", 8);
    full.push_back("--gif");
    full.push_back((dir / "full.gif").string());
    REQUIRE(runSplat(full).status == 0);
    // An interrupted run: some frames are there, others not.
    auto part = rotateArgs(dir / "part", 8);
    REQUIRE(runSplat(part).status == 0);
    fs::remove(dir / "part" / "frame_0002.png");
    fs::remove(dir / "part" / "frame_0006.png");
    const auto kept = fs::last_write_time(dir / "part" / "frame_0000.png");
    part.push_back("--resume");
    part.push_back("--gif");
    part.push_back((dir / "part.gif").string());
    const RunResult r = runSplat(part);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("wrote 2 frames") != std::string::npos);
    CHECK(fs::last_write_time(dir / "part" / "frame_0000.png") == kept);
    // The finished sequence is the full run's, frame for frame (pixel for pixel: the
    // files' metadata name their own folders) and in the GIF.
    for (int f = 0; f < 8; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%04d.png", f);
        const splat::Image a = splat::readImage((dir / "part" / name).string());
        const splat::Image b = splat::readImage((dir / "full" / name).string());
        REQUIRE(a.pixels.size() == b.pixels.size());
        CHECK(std::equal(a.pixels.begin(), a.pixels.end(), b.pixels.begin()));
    }
    CHECK(readTextFile(dir / "part.gif") == readTextFile(dir / "full.gif"));
}

TEST_CASE("rotate: a folder with foreign frames is refused without --overwrite", "[cli][rotate]") {
    const fs::path dir = testTmpDir("rotate_foreign");
    fs::remove_all(dir);
    REQUIRE(runSplat(rotateArgs(dir, 4)).status == 0);
    // Frames already there: a new run must say what to do.
    RunResult r = runSplat(rotateArgs(dir, 4));
    CHECK(r.status == 1);
    REQUIRE(r.errLines().size() == 1);
    CHECK(r.err.find("--overwrite") != std::string::npos);
    // Other settings cannot be resumed into the folder.
    auto other = rotateArgs(dir, 4);
    other[3] = "ct-bone";
    other.push_back("--resume");
    r = runSplat(other);
    CHECK(r.status == 1);
    CHECK(r.err.find("other settings") != std::string::npos);
    // A frame beyond the sequence would be stale.
    auto fewer = rotateArgs(dir, 2);
    fewer.push_back("--resume");
    CHECK(runSplat(fewer).status == 1);
    // --overwrite replaces them, and removes the stale ones.
    fewer.back() = "--overwrite";
    REQUIRE(runSplat(fewer).status == 0);
    CHECK(countFiles(dir, ".png") == 2);
}

TEST_CASE("rotate: camera paths and refusals before any work", "[cli][rotate]") {
    const fs::path dir = testTmpDir("rotate_path");
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "path.json")
        << R"({"keys": [{"azimuth": 0, "elevation": 0}, {"azimuth": 90, "elevation": 30}]})";
    auto args = rotateArgs(dir / "frames", 4);
    args.push_back("--path");
    args.push_back((dir / "path.json").string());
    REQUIRE(runSplat(args).status == 0);
    CHECK(countFiles(dir / "frames", ".png") == 4);
    std::ofstream(dir / "bad.json") << R"({"keys": [{"azimuth": 0, "zoom": 2}, {"azimuth": 9}]})";
    args.back() = (dir / "bad.json").string();
    args[9] = (dir / "bad").string();
    RunResult r = runSplat(args);
    CHECK(r.status == 1);
    CHECK(r.err.find("'zoom'") != std::string::npos);
    CHECK(!fs::exists(dir / "bad"));  // nothing created
    auto gifWrong = rotateArgs(dir / "g", 2);
    gifWrong.push_back("--gif");
    gifWrong.push_back((dir / "x.png").string());
    r = runSplat(gifWrong);
    CHECK(r.status == 2);  // a malformed value: usage error
    CHECK(!fs::exists(dir / "g"));
    auto badName = rotateArgs(dir / "n", 2);
    badName.push_back("--name");
    badName.push_back("frame");
    CHECK(runSplat(badName).status == 2);
}
