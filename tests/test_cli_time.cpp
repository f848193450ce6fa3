// The command line on a time series: --time T on render, a step past the last a usage error
// (exit 2), and `rotate --time-steps A:B` writing one frame per step, each the image `render
// --time` gives for that step (camera fixed), or turning as --from/--to say.
#include <catch2/catch.hpp>
#include <filesystem>

#include "cli_util.h"
#include "image_diff.h"
#include "splat/image_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

TEST_CASE("cli: --time and rotate --time-steps on a 4D NRRD", "[cli][time]") {
    const fs::path dir = testTmpDir("cli_time");
    fs::remove_all(dir);
    fs::create_directories(dir);
    // A ball of radius 2 + 2t around the centre of a 16^3 grid, background 10.
    std::vector<double> values;
    for (int t = 0; t < 3; ++t)
        for (int z = 0; z < 16; ++z)
            for (int y = 0; y < 16; ++y)
                for (int x = 0; x < 16; ++x) {
                    const double r = std::sqrt((x - 7.5) * (x - 7.5) + (y - 7.5) * (y - 7.5) +
                                               (z - 7.5) * (z - 7.5));
                    values.push_back(r < 2 + 2 * t ? 100 + t : 10);
                }
    const std::string nrrd = (dir / "ball.nrrd").string();
    writeBytes(nrrd,
               "NRRD0004\ntype: float\ndimension: 4\nsizes: 16 16 16 3\nkinds: domain domain "
               "domain time\nendian: little\nencoding: raw\n\n" +
                   samples<float>(values));
    const std::vector<std::string> view = {"--mode", "xray", "--size", "24x20", "--azimuth", "30"};
    auto with = [&](std::vector<std::string> a) {
        a.insert(a.end(), view.begin(), view.end());
        return a;
    };
    for (int t = 0; t < 3; ++t)
        REQUIRE(runSplat(with({"render", nrrd, "--time", std::to_string(t), "-o",
                               (dir / ("step" + std::to_string(t) + ".exr")).string()}))
                    .status == 0);
    const RunResult out =
        runSplat(with({"render", nrrd, "--time", "3", "-o", (dir / "x.exr").string()}));
    CHECK(out.status == 2);
    CHECK_THAT(out.err, Catch::Contains("time step 3 is out of range: it holds time steps 0 to 2"));
    CHECK(runSplat(with({"render", nrrd, "--time", "-1", "-o", (dir / "x.exr").string()})).status ==
          2);
    // Bricks read the step by byte ranges (the sample layout): the same image, the same error.
    REQUIRE(runSplat(with({"render", nrrd, "--time", "2", "--bricks", "2", "-o",
                           (dir / "bricks2.exr").string()}))
                .status == 0);
    CHECK(maxDiff(readImage((dir / "step2.exr").string()),
                  readImage((dir / "bricks2.exr").string())) <=
          1e-5f * peakOf(readImage((dir / "step2.exr").string())));
    CHECK(runSplat(with({"render", nrrd, "--time", "3", "--bricks", "2", "-o",
                         (dir / "x.exr").string()}))
              .status == 2);

    // One frame per step, the camera fixed: frame f is step f's image.
    const RunResult r = runSplat(with({"rotate", nrrd, "--time-steps", "0:2", "--format", "exr",
                                       "-q", "-o", (dir / "frames").string()}));
    INFO(r.err);
    REQUIRE(r.status == 0);
    for (int f = 0; f < 3; ++f) {
        const Image step = readImage((dir / ("step" + std::to_string(f) + ".exr")).string());
        const Image frame =
            readImage((dir / "frames" / ("frame_000" + std::to_string(f) + ".exr")).string());
        CHECK(maxDiff(step, frame) == 0.0f);
    }
    // The steps differ (the ball grows), so the frames are not one image three times.
    CHECK(maxDiff(readImage((dir / "step0.exr").string()),
                  readImage((dir / "step2.exr").string())) > 1.0f);
    // Past the last step: a usage error before any frame is written; --frames must agree.
    const RunResult past = runSplat(
        with({"rotate", nrrd, "--time-steps", "1:3", "-q", "-o", (dir / "past").string()}));
    CHECK(past.status == 2);
    CHECK_FALSE(fs::exists(dir / "past" / "frame_0000.png"));
    CHECK(runSplat(with({"rotate", nrrd, "--time-steps", "0:2", "--frames", "4", "-o",
                         (dir / "f4").string()}))
              .status == 2);
    // Turning over the sequence: the last frame is step 2 seen from --to.
    REQUIRE(runSplat({"rotate", nrrd, "--time-steps", "0:2", "--from", "0", "--to", "60", "--mode",
                      "xray", "--size", "24x20", "--format", "exr", "-q", "-o",
                      (dir / "turn").string()})
                .status == 0);
    REQUIRE(runSplat({"render", nrrd, "--time", "2", "--azimuth", "60", "--mode", "xray", "--size",
                      "24x20", "-o", (dir / "turn2.exr").string()})
                .status == 0);
    CHECK(maxDiff(readImage((dir / "turn2.exr").string()),
                  readImage((dir / "turn" / "frame_0002.exr").string())) == 0.0f);
}
