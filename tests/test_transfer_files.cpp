// Transfer-function files (ParaView's colour-map presets, presets carrying their mode,
// refused typos and absurd numbers). Files are written by the tests.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "cli_util.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/metrics.h"
#include "splat/render.h"
#include "splat/synthetic.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

std::string writeFile(const std::string& name, const std::string& text) {
    const fs::path p = testTmpDir("transfer_files_" + name) / name;
    std::ofstream(p) << text;
    return p.string();
}

std::string errorOf(const std::string& path) {
    try {
        TransferFunction::load(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// What ParaView 5.x writes with "Save preset" / "Export" for a CT colour map edited in the
// colour map editor (opacity included), absolute Hounsfield units.
const char* kParaViewCt = R"([
  {
    "ColorSpace" : "RGB",
    "Creator" : "Kitware Inc.",
    "DefaultMap" : false,
    "Name" : "CT-Edited",
    "NanColor" : [ 1, 1, 0 ],
    "NanOpacity" : 1,
    "Points" : [ -1000, 0, 0.5, 0, 0, 0.2, 0.5, 0, 400, 0.6, 0.5, 0, 3000, 0.8, 0.5, 0 ],
    "RGBPoints" : [ -1000, 0, 0, 0, 200, 1, 0.5, 0.2, 3000, 1, 1, 1 ]
  }
]
)";

}  // namespace

TEST_CASE("ParaView colour map presets: colours and opacities at given data values", "[transfer]") {
    const TransferFunction tf = TransferFunction::load(writeFile("ct.json", kParaViewCt));
    CHECK(tf.name == "CT-Edited");
    CHECK_FALSE(tf.normalized);  // ParaView's values are absolute data values
    CHECK(tf.unitDistance == 1.0);
    CHECK_FALSE(tf.mode);
    // Colour nodes at -1000, 200, 3000; opacity nodes at -1000, 0, 400, 3000 (the union).
    auto near = [](glm::vec4 a, glm::vec4 b) {
        INFO(a.r << " " << a.g << " " << a.b << " " << a.a << " vs " << b.r << " " << b.g << " "
                 << b.b << " " << b.a);
        CHECK(glm::length(a - b) < 1e-5f);
    };
    near(tf.sample(-1000), {0, 0, 0, 0});
    near(tf.sample(-400), {0.5f, 0.25f, 0.1f, 0.12f});  // colour halfway; opacity 0.6 of 0.2
    near(tf.sample(0), {1000.0f / 1200, 500.0f / 1200, 200.0f / 1200, 0.2f});
    near(tf.sample(200), {1, 0.5f, 0.2f, 0.4f});
    near(tf.sample(1600), {1, 0.75f, 0.6f, 0.6f + 0.2f * 1200 / 2600});
    near(tf.sample(5000), {1, 1, 1, 0.8f});  // clamped beyond the last node
    // The absolute domain: resolve() leaves it alone; --tf-rescale stretches -1000..3000 over
    // the volume's range (ParaView's "rescale to data range").
    near(tf.resolved(0, 1).sample(200), tf.sample(200));
    const TransferFunction r = tf.rescaledToData().resolved(0, 100);
    near(r.sample(30), tf.sample(200));  // 200 is 30% of -1000..3000
}

TEST_CASE("ParaView presets: colour spaces, midpoint and sharpness, steps, several presets",
          "[transfer]") {
    auto one = [](const std::string& space, const std::string& rgb, const std::string& pts = "") {
        std::string text =
            "[{\"Name\": \"t\", \"ColorSpace\": \"" + space + "\", \"RGBPoints\": [" + rgb + "]";
        if (!pts.empty()) text += ", \"Points\": [" + pts + "]";
        return TransferFunction::load(writeFile("space.json", text + "}]"));
    };
    // Moreland's diverging cool-to-warm through grey L* = 88 at the middle: 0.8654 in sRGB
    // (ParaView's own "Cool to Warm" lists 0.865003 there).
    const TransferFunction cw =
        one("Diverging", "0, 0.231373, 0.298039, 0.752941, 1, 0.705882, 0.0156863, 0.14902");
    for (int c = 0; c < 3; ++c) CHECK(std::abs(cw.sample(0.5f)[c] - 0.8654f) < 0.003f);
    CHECK(cw.sample(0.0f).b == Approx(0.752941f));
    // CIELAB: black to white is L* 50 at the middle, sRGB 0.4663.
    const TransferFunction lab = one("Lab", "0, 0, 0, 0, 1, 1, 1, 1");
    CHECK(lab.sample(0.5f).g == Approx(0.4663f).margin(0.002));
    // HSV: red to blue the short way round is magenta in the middle.
    const TransferFunction hsv = one("HSV", "0, 1, 0, 0, 1, 0, 0, 1");
    CHECK(hsv.sample(0.5f).r == Approx(1.0f).margin(1e-5));
    CHECK(hsv.sample(0.5f).g == Approx(0.0f).margin(1e-5));
    CHECK(hsv.sample(0.5f).b == Approx(1.0f).margin(1e-5));
    // vtkPiecewiseFunction: the midpoint is where the opacity is halfway (here at a quarter
    // of the segment), sharpness 1 is a step there.
    const TransferFunction mid =
        one("RGB", "0, 1, 1, 1, 8, 1, 1, 1", "0, 0, 0.25, 0, 8, 1, 0.5, 0");
    CHECK(mid.sample(2.0f).a == Approx(0.5f).margin(1e-6));
    CHECK(mid.sample(1.0f).a == Approx(0.25f).margin(1e-6));
    const TransferFunction sharp =
        one("RGB", "0, 1, 1, 1, 8, 1, 1, 1", "0, 0, 0.5, 1, 8, 1, 0.5, 0");
    CHECK(sharp.sample(3.75f).a == 0.0f);
    CHECK(sharp.sample(4.25f).a == 1.0f);
    // Without "Points" the opacity is ParaView's default ramp 0..1 over the colour range.
    CHECK(one("RGB", "10, 0, 0, 0, 30, 1, 1, 1").sample(15.0f).a == Approx(0.25f));
    // A step (the same x twice) stays a step.
    const TransferFunction step = one("RGB", "0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 1, 2, 0, 0, 1");
    CHECK(step.sample(0.999f).r == 1.0f);
    CHECK(step.sample(1.001f).b == 1.0f);
    // Several presets: one is chosen by name.
    const std::string two = writeFile("two.json",
                                      R"([{"Name": "A", "RGBPoints": [0, 1, 0, 0, 1, 1, 0, 0]},
            {"Name": "B", "RGBPoints": [0, 0, 1, 0, 1, 0, 1, 0]}])");
    CHECK(errorOf(two).find("FILE.json#Name (A, B)") != std::string::npos);
    CHECK(TransferFunction::load(two + "#B").sample(0.5f).g == 1.0f);
    CHECK(errorOf(two + "#C").find("no ParaView preset named 'C'") != std::string::npos);
}

TEST_CASE("a ParaView preset renders like the same function in the project's format",
          "[transfer]") {
    const TransferFunction pv = TransferFunction::load(writeFile("ct.json", kParaViewCt));
    std::string own = "{\"domain\": \"absolute\", \"unit_distance\": 1, \"points\": [";
    for (std::size_t n = 0; n < pv.points.size(); ++n) {
        const TransferPoint& p = pv.points[n];
        char buf[200];
        std::snprintf(buf, sizeof buf, "%s[%.9g, %.9g, %.9g, %.9g, %.9g]", n ? ", " : "",
                      double(p.value), double(p.rgba.r), double(p.rgba.g), double(p.rgba.b),
                      double(p.rgba.a));
        own += buf;
    }
    const TransferFunction mine = TransferFunction::load(writeFile("own.json", own + "]}"));
    Volume v = makeSynthetic("blob", 16);
    for (float& d : v.data) d = -1000.0f + 4000.0f * d;  // to Hounsfield-like units
    RenderSettings s;
    s.camera.width = s.camera.height = 24;
    s.threads = 2;
    s.transfer = pv;
    const Image a = render(v, s);
    s.transfer = mine;
    const Image b = render(v, s);
    CHECK(a.pixels == b.pixels);
    float peak = 0;
    for (const auto& p : a.pixels) peak = std::max(peak, p.a);
    CHECK(peak > 0.1f);
}

TEST_CASE("transfer function files: typos and absurd numbers are refused naming file and key",
          "[transfer]") {
    auto file = [](const std::string& body) { return writeFile("bad.json", body); };
    const std::string points = "\"points\": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 0.5]]";
    std::string path = file("{\"unit-distance\": 2, " + points + "}");
    std::string e = errorOf(path);
    CHECK(e.find(path) != std::string::npos);
    CHECK(e.find("unknown key \"unit-distance\"") != std::string::npos);
    // unit_distance 1e-300 gave NaN pixels: refused, as is anything outside [1e-6, 1e6].
    for (const char* u : {"1e-300", "1e-7", "2e6", "0", "-1"})
        CHECK(errorOf(file(std::string("{\"unit_distance\": ") + u + ", " + points + "}"))
                  .find("unit_distance must be a number in [1e-6, 1e6]") != std::string::npos);
    CHECK(errorOf(file("{\"points\": [[0, 0, 0, 0, 0], [1, 1.5, 1, 1, 0.5]]}"))
              .find("outside [0, 1]") != std::string::npos);
    CHECK(errorOf(file("{\"points\": [[0, 0, 0, 0, -0.1], [1, 1, 1, 1, 0.5]]}"))
              .find("outside [0, 1]") != std::string::npos);
    CHECK(
        errorOf(file("{\"points\": [[0, 0, 0, 0, 0], [1e39, 1, 1, 1, 0.5]]}")).find("non-finite") !=
        std::string::npos);
    CHECK(errorOf(file("{\"points\": [[1, 0, 0, 0, 0], [0, 1, 1, 1, 0.5]]}"))
              .find("non-decreasing (point 1)") != std::string::npos);
    CHECK(errorOf(file("{\"mode\": \"mpi\", " + points + "}")).find("\"mode\"") !=
          std::string::npos);
    CHECK(errorOf(file("[{\"Name\": \"x\", \"RGBPoint\": [0, 0, 0, 0]}]"))
              .find("unknown ParaView preset key \"RGBPoint\"") != std::string::npos);
    CHECK(errorOf(file("[{\"RGBPoints\": [0, 0, 0, 0, 1, 2, 0, 0]}]")).find("outside [0, 1]") !=
          std::string::npos);
    CHECK(errorOf(file("[{\"RGBPoints\": [0, 0, 0, 0, 1, 1, 0, 0], \"ColorSpace\": \"Step\"}]"))
              .find("not supported") != std::string::npos);
    // A hostile node count is refused before anything is resampled.
    std::string many = "[{\"RGBPoints\": [";
    for (int q = 0; q <= 65536; ++q) many += (q ? ", " : "") + std::to_string(q) + ", 0, 0, 0";
    CHECK(errorOf(file(many + "]}]")).find("more than 65536 nodes") != std::string::npos);
    // The extremes of the accepted range render finite pixels.
    for (double u : {kMinUnitDistance, kMaxUnitDistance}) {
        RenderSettings s;
        s.camera.width = s.camera.height = 16;
        s.threads = 2;
        s.transfer.unitDistance = u;
        for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet, RendererKind::Reference})
            for (Classification c : {Classification::Pre, Classification::Post}) {
                s.renderer = r;
                s.classification = c;
                const Image img = render(makeSynthetic("blob", 12), s);
                for (const auto& p : img.pixels)
                    REQUIRE((std::isfinite(p.r) && std::isfinite(p.a) && p.a <= 1.0f));
            }
    }
}

TEST_CASE("presets carry their mode; an explicit --mode wins with a warning", "[transfer][cli]") {
    CHECK(*TransferFunction::preset("mip-gray").mode == RenderMode::Mip);
    CHECK(*TransferFunction::preset("xray").mode == RenderMode::Xray);
    CHECK_FALSE(TransferFunction::preset("ct-bone").mode);
    // The rule (library): the function's mode unless one was chosen explicitly.
    const TransferFunction mipTf = TransferFunction::preset("mip-gray");
    std::string w;
    CHECK(modeFor(mipTf, RenderMode::Dvr, false, &w) == RenderMode::Mip);
    CHECK(w.empty());
    CHECK(modeFor(mipTf, RenderMode::Mip, true, &w) == RenderMode::Mip);
    CHECK(w.empty());
    CHECK(modeFor(mipTf, RenderMode::Xray, true, &w) == RenderMode::Xray);
    CHECK(w == "--mode xray overrides the mode mip of transfer function 'mip-gray'");
    CHECK(modeFor(TransferFunction::preset("ct-bone"), RenderMode::Iso, false) == RenderMode::Iso);
    const fs::path dir = testTmpDir("transfer_mode");
    auto run = [&](std::vector<std::string> extra, const std::string& out) {
        std::vector<std::string> args{"render", "synthetic:blob:16", "--size", "24x24",
                                      "-o",     (dir / out).string()};
        args.insert(args.end(), extra.begin(), extra.end());
        return runSplat(args);
    };
    const RunResult preset = run({"--tf", "mip-gray"}, "preset.exr");
    INFO(preset.err);
    REQUIRE(preset.status == 0);
    CHECK(preset.err.empty());
    REQUIRE(run({"--mode", "mip"}, "mip.exr").status == 0);
    CHECK(readImage((dir / "preset.exr").string()).pixels ==
          readImage((dir / "mip.exr").string()).pixels);
    // Explicit and disagreeing: the explicit mode, and one warning line.
    const RunResult both = run({"--tf", "xray", "--mode", "dvr"}, "dvr.exr");
    REQUIRE(both.status == 0);
    REQUIRE(both.errLines().size() == 1);
    CHECK(both.errLines()[0] ==
          "splat: warning: --mode dvr overrides the mode xray of transfer function 'xray'");
    REQUIRE(run({}, "plain.exr").status == 0);
    CHECK(readImage((dir / "dvr.exr").string()).pixels !=
          readImage((dir / "mip.exr").string()).pixels);
    // Explicit and agreeing: silent. A JSON file's "mode" works like a preset's.
    CHECK(run({"--tf", "xray", "--mode", "xray"}, "x.exr").err.empty());
    const std::string tf = (dir / "mip.json").string();
    std::ofstream(tf) << R"({"mode": "mip", "points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 0.1]]})";
    REQUIRE(run({"--tf", tf}, "file.exr").status == 0);
    CHECK(readImage((dir / "file.exr").string()).pixels ==
          readImage((dir / "mip.exr").string()).pixels);
    // --tf-rescale: ParaView's "rescale to data range": a function over 0..2 stretched over
    // the blob's [min, max] renders like the same function written over [min, max]; ignored
    // with a warning for the presets, which are normalized already.
    const std::string wide = (dir / "wide.json").string();
    std::ofstream(wide) << R"([{"Name": "w", "RGBPoints": [0, 1, 1, 1, 2, 1, 1, 1],
                                "Points": [0, 0, 0.5, 0, 2, 0.2, 0.5, 0]}])";
    const VolumeStats st = volumeStats(makeSynthetic("blob", 16));
    char range[200];
    std::snprintf(range, sizeof range,
                  R"([{"Name": "n", "RGBPoints": [%.9g, 1, 1, 1, %.9g, 1, 1, 1],
                      "Points": [%.9g, 0, 0.5, 0, %.9g, 0.2, 0.5, 0]}])",
                  double(st.minValue), double(st.maxValue), double(st.minValue),
                  double(st.maxValue));
    const std::string narrow = (dir / "narrow.json").string();
    std::ofstream(narrow) << range;
    REQUIRE(run({"--tf", wide, "--tf-rescale"}, "wide.exr").status == 0);
    REQUIRE(run({"--tf", narrow}, "narrow.exr").status == 0);
    REQUIRE(run({"--tf", wide}, "wide0.exr").status == 0);
    const Image rescaled = readImage((dir / "wide.exr").string());
    CHECK(compareImages(rescaled, readImage((dir / "narrow.exr").string())).maxAbs < 1e-6);
    CHECK(compareImages(rescaled, readImage((dir / "wide0.exr").string())).maxAbs > 0.01);
    const RunResult normalized = run({"--tf", "ct-bone", "--tf-rescale"}, "bone.exr");
    REQUIRE(normalized.errLines().size() == 1);
    CHECK(normalized.err.find("already on the volume's normalized range; ignored") !=
          std::string::npos);
    // A typo in a transfer function file is one error line naming the key.
    std::ofstream(dir / "typo.json") << R"({"unit-distance": 1, "points": [[0, 0, 0, 0, 0]]})";
    const RunResult typo = run({"--tf", (dir / "typo.json").string()}, "typo.exr");
    CHECK(typo.status != 0);
    REQUIRE(typo.errLines().size() == 1);
    CHECK(typo.err.find("unknown key \"unit-distance\"") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "typo.exr"));
}
