// The command line's contract with scripts (docs/command-line.md): exit status 0 success,
// 1 the work failed, 2 usage error, for every subcommand; usage text on a bare `splat`;
// grouped --help; --version; one warning line per ignored flag with the image unchanged;
// compare --fail-above; Volume::note warnings from every command that loads a volume; the
// bash completion script.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "cli_util.h"
#include "splat/version.h"

using namespace splat::test;
namespace fs = std::filesystem;

namespace {

void requireUsageLine(const RunResult& r, const std::string& text) {
    INFO("stderr: " << r.err);
    CHECK(r.status == 2);
    REQUIRE(r.errLines().size() == 1);
    CHECK(r.errLines()[0].rfind("splat: error:", 0) == 0);
    CHECK(r.err.find(text) != std::string::npos);
}

std::vector<std::string> warnings(const RunResult& r) {
    std::vector<std::string> w;
    for (const std::string& l : r.errLines())
        if (l.rfind("splat: warning:", 0) == 0) w.push_back(l);
    return w;
}

}  // namespace

TEST_CASE("bare splat, unknown commands, bad flags and bad values exit with status 2",
          "[cli][exit]") {
    const RunResult bare = runSplat({});
    CHECK(bare.status == 2);
    for (const char* c : {"usage:", "info", "render", "rotate", "compare", "bench", "popping",
                          "study", "slices", "mpr", "cpr"})
        CHECK(bare.err.find(c) != std::string::npos);
    CHECK(bare.err.find("completion") == std::string::npos);  // hidden

    requireUsageLine(runSplat({"rendr"}), "did you mean 'render'?");
    requireUsageLine(runSplat({"frobnicate"}), "unknown command 'frobnicate'");

    const fs::path dir = testTmpDir("cli_exit");
    const std::string out = (dir / "o.png").string();
    requireUsageLine(runSplat({"render", "synthetic:blob:8", "--frobnicate", "-o", out}),
                     "--frobnicate");
    requireUsageLine(runSplat({"render", "synthetic:blob:8", "--size", "banana", "-o", out}),
                     "--size");
    requireUsageLine(runSplat({"render", "synthetic:blob:8", "--azimuth", "east", "-o", out}),
                     "--azimuth");
    requireUsageLine(runSplat({"render", "-o", out}), "VOLUME");
    CHECK(!fs::exists(out));
    // The same for every subcommand: an unknown option is a usage error.
    for (const char* c : {"info", "render", "rotate", "compare", "bench", "popping", "study",
                          "slices", "mpr", "cpr"}) {
        INFO(c);
        CHECK(runSplat({c, "--no-such-option"}).status == 2);
    }
}

TEST_CASE("a render that fails exits with status 1 and one line", "[cli][exit]") {
    const fs::path dir = testTmpDir("cli_exit_fail");
    const std::string out = (dir / "o.png").string();
    RunResult r = runSplat({"render", (dir / "missing.nii").string(), "-o", out});
    INFO(r.err);
    CHECK(r.status == 1);
    CHECK(r.errLines().size() == 1);
    CHECK(!fs::exists(out));
    // Well-formed options the renderer cannot honour: a work failure too.
    r = runSplat({"render", "synthetic:blob:8", "--size", "30000x30000", "-o", out});
    CHECK(r.status == 1);
    CHECK(r.errLines().size() == 1);
    CHECK(r.err.find("Mpixels") != std::string::npos);
    CHECK(!fs::exists(out));
}

TEST_CASE("every numeric flag is checked before any work", "[cli][exit]") {
    const fs::path dir = testTmpDir("cli_exit_values");
    const std::string out = (dir / "o.png").string();
    const std::vector<std::vector<std::string>> bad = {
        {"--window", "0,inf", "--mode", "mip"},
        {"--window", "nan,1", "--mode", "mip"},
        {"--iso-level", "nan", "--mode", "iso"},
        {"--iso-level", "0.4q", "--mode", "iso"},
        {"--azimuth", "inf"},
        {"--pixel-size", "-1"},
        {"--fov", "0", "--projection", "perspective"},
        {"--threads", "2000"},
        {"--tile-size", "1"},
        {"--ref-step", "1e-9", "--renderer", "reference"},
        {"--sigma", "-2"},
        {"--ambient", "nan", "--shade"},
        {"--background", "0,0,2"},
        {"--header-bytes", "-1"},
        {"--slab", "0", "--renderer", "sheet"},
    };
    for (const auto& b : bad) {
        std::vector<std::string> args{"render", "synthetic:blob:8", "--size", "8x8", "-o", out};
        args.insert(args.end(), b.begin(), b.end());
        INFO(b[0] << " " << b[1]);
        requireUsageLine(runSplat(args), b[0]);
        CHECK(!fs::exists(out));
    }
    // rotate: refused before the folder is created and before any frame is rendered.
    const fs::path frames = dir / "frames";
    for (const auto& extra :
         std::vector<std::vector<std::string>>{{"--fps", "0"},
                                               {"--fps", "-5"},
                                               {"--tile-size", "1"},
                                               {"--gif", (dir / "x.png").string()},
                                               {"--frames", "0"}}) {
        std::vector<std::string> args{
            "rotate", "synthetic:blob:8", "--size", "8x8", "--frames", "2", "-q",
            "-o",     frames.string()};
        args.insert(args.end(), extra.begin(), extra.end());
        INFO(extra[0] << " " << extra[1]);
        const RunResult r = runSplat(args);
        CHECK(r.status == 2);
        CHECK(r.errLines().size() == 1);
        CHECK(!fs::exists(frames));
    }
    // An unwritable GIF (its folder would be below a file) fails before any frame: status 1.
    std::ofstream(dir / "file.txt") << "x";
    const RunResult r =
        runSplat({"rotate", "synthetic:blob:8", "--size", "8x8", "--frames", "2", "-q", "-o",
                  frames.string(), "--gif", (dir / "file.txt" / "a.gif").string()});
    CHECK(r.status == 1);
    CHECK(r.errLines().size() == 1);
    CHECK(!fs::exists(frames));
}

TEST_CASE("help is grouped with defaults and examples; version names the build", "[cli][exit]") {
    const RunResult h = runSplat({"render", "--help"});
    CHECK(h.status == 0);
    for (const char* g :
         {"Volume:", "Classification:", "Camera:", "Renderer:", "Quality:", "Output:", "Scene:",
          "Examples:", "--renderer TEXT=axis", "--slab FLOAT=1", "--iso-level TEXT=0.5n"})
        CHECK(h.out.find(g) != std::string::npos);
    const RunResult b = runSplat({"bench", "--help"});
    CHECK(b.status == 0);
    CHECK(b.out.find("--thread-list") != std::string::npos);
    for (const char* irrelevant : {"--window", "--bit-depth", "--alpha", "--output"})
        CHECK(b.out.find(irrelevant) == std::string::npos);
    const RunResult v = runSplat({"--version"});
    CHECK(v.status == 0);
    CHECK(v.out.find(std::string("splat ") + splat::kVersion) == 0);
    CHECK(v.out.find("compiler: ") != std::string::npos);
    CHECK(v.out.find("SIMD: ") != std::string::npos);
}

TEST_CASE("each ignored flag prints one warning line and leaves the image unchanged",
          "[cli][exit][warnings]") {
    const fs::path dir = testTmpDir("cli_ignored");
    struct Case {
        std::vector<std::string> base, flag;
        std::string ext, text;
    };
    const Case cases[] = {
        {{"--mode", "mip"}, {"--shade"}, ".png", "shading does not apply to mip"},
        {{"--mode", "xray"}, {"--order", "btf"}, ".exr", "--order applies to dvr only"},
        {{"--mode", "mip"}, {"--order", "btf"}, ".png", "--order applies to dvr only"},
        {{"--mode", "iso"}, {"--order", "btf"}, ".png", "--order applies to dvr only"},
        {{"--mode", "mip"}, {"--classify", "post"}, ".png", "--classify post does not apply"},
        {{"--mode", "mip"}, {"--edges", "1"}, ".png", "edge enhancement"},
        {{}, {"--window", "0,0.5"}, ".png", "--window applies to mip and xray"},
        {{"--mode", "mip"}, {"--window", "0,0.5"}, ".exr", "--window applies to 8-bit"},
        {{}, {"--slab", "0.5"}, ".png", "--slab applies to the sheet renderer"},
        {{"--renderer", "sheet"}, {"--ref-step", "0.1"}, ".png", "--ref-step applies"},
        {{}, {"--ref-tolerance", "0.01"}, ".png", "--ref-tolerance applies"},
        {{"--renderer", "reference"}, {"--tile-size", "16"}, ".png", "--tile-size applies"},
        {{"--renderer", "reference"}, {"--early-termination", "0.1"}, ".png", "splatters"},
        {{"--order", "btf"}, {"--early-termination", "0.1"}, ".png", "front-to-back"},
        {{}, {"--iso-level", "0.3"}, ".png", "--iso-level applies to iso mode only"},
        {{}, {"--iso-normalized"}, ".png", "--iso-normalized applies to iso mode only"},
        {{}, {"--ambient", "0.5"}, ".png", "--ambient given without --shade"},
        {{"--mode", "xray"}, {"--light", "1,0,0"}, ".png", "--light does not apply to xray"},
        {{}, {"--fov", "40"}, ".png", "--fov applies to --projection perspective"},
        {{}, {"--distance", "100"}, ".png", "--distance applies to --projection perspective"},
        {{}, {"--bit-depth", "16"}, ".exr", "--bit-depth applies to .png"},
        {{}, {"--alpha"}, ".tif", "--alpha applies to .png"},
    };
    for (const Case& c : cases) {
        const std::string out = (dir / ("img" + c.ext)).string();
        std::vector<std::string> args{
            "render", "synthetic:phantom:16", "--size", "24x24", "--tf", "ct-soft", "-o", out};
        args.insert(args.end(), c.base.begin(), c.base.end());
        INFO(c.flag[0]);
        const RunResult plain = runSplat(args);
        REQUIRE(plain.status == 0);
        CHECK(warnings(plain).empty());
        const std::string before = readTextFile(out);
        args.insert(args.end(), c.flag.begin(), c.flag.end());
        const RunResult with = runSplat(args);
        INFO(with.err);
        REQUIRE(with.status == 0);
        REQUIRE(warnings(with).size() == 1);
        CHECK(warnings(with)[0].find(c.text) != std::string::npos);
        CHECK(readTextFile(out) == before);  // byte for byte, metadata included
    }
    // An applicable flag is silent.
    const RunResult ok = runSplat({"render", "synthetic:blob:8", "--size", "16x16", "--shade", "-o",
                                   (dir / "s.png").string()});
    CHECK(ok.status == 0);
    CHECK(ok.err.empty());
}

TEST_CASE("compare --fail-above exits 1 above the threshold and 0 below it", "[cli][exit]") {
    const fs::path dir = testTmpDir("cli_fail_above");
    const std::string a = (dir / "a.exr").string(), b = (dir / "b.exr").string();
    REQUIRE(runSplat({"render", "synthetic:blob:16", "--size", "24x24", "-o", a}).status == 0);
    REQUIRE(runSplat({"render", "synthetic:blob:16", "--size", "24x24", "--azimuth", "20",
                      "--elevation", "30", "--mode", "mip", "-o", b})
                .status == 0);
    // Identical images: rmse 0 is not above 1e-3.
    RunResult r = runSplat({"compare", a, a, "--fail-above", "rmse=1e-3"});
    CHECK(r.status == 0);
    CHECK(r.err.empty());
    // Different images: their rmse is above 1e-3.
    r = runSplat({"compare", a, b, "--fail-above", "rmse=1e-3"});
    INFO(r.out << r.err);
    CHECK(r.status == 1);
    REQUIRE(r.errLines().size() == 1);
    CHECK(r.err.find("rmse") != std::string::npos);
    // ... and below a threshold larger than it (RGB values are within [0, 1]: rmse <= 1).
    CHECK(runSplat({"compare", a, b, "--fail-above", "rmse=1", "--fail-above", "max=1"}).status ==
          0);
    CHECK(runSplat({"compare", a, b, "--fail-above", "psnr-below=1000"}).status == 1);
    CHECK(runSplat({"compare", a, a, "--fail-above", "psnr-below=1000"}).status == 0);
    CHECK(runSplat({"compare", a, a, "--fail-above", "flip=0"}).status == 0);  // FLIP 0 exactly
    r = runSplat({"compare", a, b, "--fail-above", "flip=0"});
    CHECK(r.status == 1);
    CHECK(r.out.find("flip ") != std::string::npos);
    requireUsageLine(runSplat({"compare", a, b, "--fail-above", "ssim=0.1"}), "METRIC");
    requireUsageLine(runSplat({"compare", a, b, "--fail-above", "rmse=-1"}), "rmse=-1");
    // A display PNG against a linear EXR: a warning line.
    const std::string p = (dir / "a.png").string();
    REQUIRE(runSplat({"render", "synthetic:blob:16", "--size", "24x24", "-o", p}).status == 0);
    r = runSplat({"compare", p, a});
    CHECK(r.status == 0);
    REQUIRE(warnings(r).size() == 1);
    CHECK(r.err.find("unlike quantities") != std::string::npos);
    // The heat map never overwrites an input.
    const std::string before = readTextFile(p);
    r = runSplat({"compare", p, p, "--heatmap", p});
    CHECK(r.status == 1);
    CHECK(r.errLines().size() == 1);
    CHECK(r.err.find("would overwrite the input") != std::string::npos);
    CHECK(readTextFile(p) == before);
}

TEST_CASE("every command that loads a volume prints its notes as warnings", "[cli][exit]") {
    const fs::path dir = testTmpDir("cli_notes");
    // 2x2x2 float32 with one NaN: --nan-policy zero replaces it, and the volume notes it.
    std::vector<float> v(8, 1.0f);
    v[3] = std::numeric_limits<float>::quiet_NaN();
    const fs::path raw = dir / "nan.raw";
    std::ofstream(raw, std::ios::binary)
        .write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * 4));
    const std::vector<std::string> load = {raw.string(), "--dims",       "2x2x2", "--type",
                                           "float32",    "--nan-policy", "zero"};
    const std::vector<std::vector<std::string>> commands = {
        {"info"},
        {"render", "--size", "8x8", "-o", (dir / "r.png").string()},
        {"rotate", "--size", "8x8", "--frames", "2", "-q", "-o", (dir / "f").string()},
        {"bench", "--size", "8x8", "--repeats", "1", "--thread-list", "1"},
        {"slices", "-o", (dir / "s").string()},
    };
    for (auto args : commands) {
        args.insert(args.begin() + 1, load.begin(), load.end());
        const RunResult r = runSplat(args);
        INFO(args[0] << ": " << r.err);
        CHECK(r.status == 0);
        const auto w = warnings(r);
        REQUIRE(w.size() == 1);
        CHECK(w[0].find("1 NaN/Inf samples replaced by 0") != std::string::npos);
    }
}

TEST_CASE("bench --json refuses a folder and a missing folder with one line", "[cli][exit]") {
    const fs::path dir = testTmpDir("cli_bench_json");
    for (const fs::path& target : {dir, dir / "no" / "b.json"}) {
        const RunResult r = runSplat({"bench", "synthetic:blob:8", "--size", "8x8", "--repeats",
                                      "1", "--thread-list", "1", "--json", target.string()});
        INFO(r.err);
        CHECK(r.status == 1);
        REQUIRE(r.errLines().size() == 1);
        CHECK(r.err.find("filesystem error") == std::string::npos);
        CHECK(r.out.empty());  // refused before the timing
    }
    for (const auto& e : fs::directory_iterator(dir))
        CHECK(e.path().filename().string().find(".tmp") == std::string::npos);
}

TEST_CASE("the bash completion script is generated from the CLI and installed by the build",
          "[cli][exit]") {
    const RunResult r = runSplat({"completion", "bash"});
    REQUIRE(r.status == 0);
    for (const char* word : {"info", "render", "rotate", "compare", "bench", "popping", "study",
                             "slices", "mpr", "cpr", "--renderer", "--write-scene", "--scene",
                             "--fail-above", "axis sheet reference", "complete -o filenames"})
        CHECK(r.out.find(word) != std::string::npos);
    const fs::path installed =
        fs::path(SPLAT_EXE).parent_path().parent_path() / "share/bash-completion/completions/splat";
    REQUIRE(fs::exists(installed));
    CHECK(readTextFile(installed) == r.out);
    CHECK(runSplat({"completion", "zsh"}).status == 2);
}
