// `splat info` end to end: good volumes print a description; bad input exits non-zero
// with exactly one "splat: error:" line on stderr and leaves no file behind.
#include <catch2/catch.hpp>

#include "cli_util.h"
#include "test_volume_util.h"

using namespace splat::test;

TEST_CASE("splat info synthetic:phantom:128", "[volume][cli]") {
    RunResult r = runSplat({"info", "synthetic:phantom:128"});
    INFO(r.err);
    CHECK(r.status == 0);
    CHECK_THAT(r.out, Catch::Contains("128 x 128 x 128"));
    CHECK_THAT(r.out, Catch::Contains("0 .. 2"));
    CHECK_THAT(r.out, Catch::Contains("histogram"));
    CHECK(r.err.empty());
}

TEST_CASE("splat info ch2.nii.gz", "[volume][cli]") {
    const std::string ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
    if (!std::filesystem::exists(ch2)) {
        WARN("skipped: " << ch2 << " is not installed");
        return;
    }
    RunResult r = runSplat({"info", ch2});
    INFO(r.err);
    CHECK(r.status == 0);
    CHECK_THAT(r.out, Catch::Contains("181 x 217 x 181"));
    CHECK_THAT(r.out, Catch::Contains("1 x 1 x 1 mm"));
}

TEST_CASE("splat info with raw options and nan policy", "[volume][cli]") {
    auto dir = testTmpDir("cli_info_raw");
    std::string p = (dir / "data.bin.raw").string();
    writeBytes(p, samples<std::int16_t>({1, 2, 3, 4, 5, 6}, true));
    RunResult r = runSplat({"info", p, "--dims", "3x2x1", "--type", "int16", "--big-endian",
                            "--spacing", "0.5,0.5,2"});
    INFO(r.err);
    CHECK(r.status == 0);
    CHECK_THAT(r.out, Catch::Contains("3 x 2 x 1"));
    CHECK_THAT(r.out, Catch::Contains("0.5 x 0.5 x 2 mm"));
    CHECK_THAT(r.out, Catch::Contains("1 .. 6"));

    std::string n = (dir / "n_2x1x1_float32.raw").string();
    writeBytes(n, samples<float>({1.0, std::nan("")}));
    RunResult z = runSplat({"info", n, "--nan-policy", "zero"});
    CHECK(z.status == 0);
    CHECK_THAT(z.out, Catch::Contains("1 NaN/Inf samples replaced by 0"));
}

TEST_CASE("splat info: bad input exits non-zero with one line on stderr", "[volume][cli]") {
    auto dir = testTmpDir("cli_info_bad");
    writeBytes(dir / "t_4x4x4_uint8.raw", std::string(10, 'x'));
    writeBytes(dir / "n_2x1x1_float32.raw", samples<float>({1.0, std::nan("")}));
    writeBytes(dir / "odd.xyz", "what");
    writeBytes(dir / "gz.nrrd",
               "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\n"
               "encoding: gzip\n\nnot gzip at all");
    // Eight bytes and no dimensions: raw data the name says nothing about.
    writeBytes(dir / "plain.raw", std::string(8, char(0x2a)));
    writeBytes(dir / "junk.nii", std::string(500, 'j'));
    auto before = std::distance(std::filesystem::directory_iterator(dir),
                                std::filesystem::directory_iterator());
    struct Case {
        std::vector<std::string> args;
        std::string expect;
    };
    const std::string d = dir.string() + "/";
    std::vector<Case> cases = {
        {{"info", d + "missing.nii"}, "no such file or folder"},
        {{"info", d + "t_4x4x4_uint8.raw"}, "truncated data: expected 64 bytes, found 10"},
        {{"info", d + "n_2x1x1_float32.raw"}, "1 NaN/Inf samples (first at voxel 1,0,0)"},
        {{"info", d + "odd.xyz"}, "unknown file type"},
        {{"info", d + "gz.nrrd"}, "corrupt gzip data"},
        {{"info", d + "plain.raw", "--dims", "2x2"}, "--dims '2x2'"},
        {{"info", d + "plain.raw", "--dims", "2x2x2", "--type", "quad"}, "unsupported sample type"},
        {{"info", d + "plain.raw", "--dims", "2x2x2", "--type", "u8", "--spacing", "1,0,1"},
         "spacings must be finite and > 0"},
        {{"info", "synthetic:phantom", "--nan-policy", "maybe"}, "--nan-policy 'maybe'"},
        {{"info", "synthetic:nothing"}, "unknown synthetic volume"},
        {{"info", d + "junk.nii"}, "junk.nii: not a readable NIfTI-1 file"},
    };
    for (const Case& c : cases) {
        RunResult r = runSplat(c.args);
        INFO(c.args[1] << " -> " << r.err);
        CHECK(r.status != 0);
        auto lines = r.errLines();
        REQUIRE(lines.size() == 1);
        CHECK_THAT(lines[0], Catch::StartsWith("splat: error: "));
        CHECK_THAT(lines[0], Catch::Contains(c.expect));
        CHECK(r.out.empty());
    }
    auto after = std::distance(std::filesystem::directory_iterator(dir),
                               std::filesystem::directory_iterator());
    CHECK(after == before);  // nothing written next to the inputs
}
