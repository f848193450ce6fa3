// Image metrics, heat maps and `splat compare`.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/metrics.h"

using namespace splat;
namespace fs = std::filesystem;

namespace {

fs::path tmpDir(const std::string& name) {
    const fs::path dir = fs::path(SPLAT_TEST_TMP) / ("metrics_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

}  // namespace

TEST_CASE("metrics: identical images", "[metrics]") {
    const Image a(8, 6, glm::vec4(0.25f, 0.5f, 0.75f, 1.0f));
    const ImageMetrics m = compareImages(a, a);
    CHECK(m.rmse == 0.0);
    CHECK(m.maxAbs == 0.0);
    CHECK(std::isinf(m.psnr));
    CHECK(m.foregroundPixels == 0);
    CHECK(m.meanAbsForeground == 0.0);
}

TEST_CASE("metrics: known differences", "[metrics]") {
    Image ref(10, 10, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
    Image test = ref;
    test.at(3, 4).r += 0.1f;
    test.at(5, 5).b -= 0.2f;
    test.at(5, 5).a = 0.0f;  // alpha is ignored by rmse/max, but makes a foreground pixel
    ref.at(7, 7) = glm::vec4(0.9f, 0.5f, 0.5f, 1.0f);  // foreground in the reference only
    test.at(7, 7) = ref.at(7, 7);
    const ImageMetrics m = compareImages(test, ref);
    const double sumSq = 0.1 * 0.1 + 0.2 * 0.2;
    CHECK(m.rmse == Approx(std::sqrt(sumSq / 300.0)).epsilon(1e-5));
    CHECK(m.maxAbs == Approx(0.2).epsilon(1e-5));
    CHECK(m.psnr == Approx(20.0 * std::log10(0.9 / m.rmse)).epsilon(1e-6));  // peak = 0.9
    CHECK(m.foregroundPixels == 3);
    CHECK(m.meanAbsForeground == Approx((0.1 / 3 + 0.2 / 3 + 0.0) / 3).epsilon(1e-5));
}

TEST_CASE("metrics: background colour from the corners", "[metrics]") {
    // A dvr image over a grey background: the grey corners are background.
    Image ref(16, 16, glm::vec4(0.2f, 0.2f, 0.2f, 1.0f));
    for (int y = 4; y < 12; ++y)
        for (int x = 4; x < 12; ++x) ref.at(x, y) = glm::vec4(0.7f, 0.6f, 0.5f, 1.0f);
    Image test = ref;
    for (int y = 4; y < 12; ++y)
        for (int x = 4; x < 12; ++x) test.at(x, y).g += 0.03f;
    const ImageMetrics m = compareImages(test, ref);
    CHECK(m.foregroundPixels == 64);
    CHECK(m.meanAbsForeground == Approx(0.01).epsilon(1e-4));
}

TEST_CASE("metrics: mismatched sizes and empty images", "[metrics]") {
    CHECK_THROWS_AS(compareImages(Image(4, 4), Image(4, 5)), Error);
    CHECK_THROWS_AS(writeHeatmap("/tmp/never.png", Image(4, 4), Image(5, 4)), Error);
    const ImageMetrics m = compareImages(Image(), Image());
    CHECK(m.rmse == 0.0);
    Image z(4, 4), n(4, 4);
    n.at(1, 1).r = std::numeric_limits<float>::quiet_NaN();
    CHECK(std::isinf(compareImages(n, z).maxAbs));  // non-finite pixels never compare equal
}

TEST_CASE("metrics: heat map with the inferno colour map, written atomically", "[metrics]") {
    const fs::path dir = tmpDir("heatmap");
    Image ref(32, 8, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    Image test = ref;
    for (int x = 0; x < 32; ++x) test.at(x, 4).r = float(x) / 31.0f;  // a ramp of differences
    const std::string png = (dir / "heat.png").string();
    writeHeatmap(png, test, ref);
    REQUIRE(fs::exists(png));
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
    CHECK(files == 1);  // no temporary left behind
    const Image heat = readImage(png);
    REQUIRE(heat.width == 32);
    REQUIRE(heat.height == 8);
    // inferno: 0 is near black, 1 is pale yellow: (0.99, 1.0, 0.65) as sRGB display values
    // in the PNG, (0.97, 1.0, 0.37) linear in OpenImageIO's map and the EXR.
    CHECK(heat.at(0, 0).r < 0.05f);
    CHECK(heat.at(0, 0).g < 0.05f);
    CHECK(heat.at(31, 4).r > 0.9f);
    CHECK(heat.at(31, 4).g > 0.9f);
    CHECK(heat.at(31, 4).b == Approx(0.65).margin(0.03));
    // EXR keeps the map's values as they are.
    const std::string exr = (dir / "heat.exr").string();
    writeHeatmap(exr, test, ref);
    const Image top = readImage(exr);
    CHECK(top.at(31, 4).r == Approx(0.97).margin(0.02));
    CHECK(top.at(31, 4).g == Approx(1.0).margin(0.02));
    CHECK(top.at(31, 4).b == Approx(0.37).margin(0.02));
    // A fixed scale twice the max: the largest difference sits mid-map (red-purple,
    // about (0.73, 0.21, 0.33) in sRGB, (0.50, 0.04, 0.09) linear).
    writeHeatmap(exr, test, ref, 2.0);
    const Image half = readImage(exr);
    CHECK(half.at(31, 4).r == Approx(0.50).margin(0.03));
    CHECK(half.at(31, 4).g == Approx(0.04).margin(0.02));
    CHECK(half.at(31, 4).b == Approx(0.09).margin(0.02));
    CHECK_THROWS_AS(writeHeatmap((dir / "missing" / "x.png").string(), test, ref), Error);
}

TEST_CASE("splat compare: metrics, JSON, heat map and bad input", "[metrics][cli]") {
    const fs::path dir = tmpDir("cli");
    Image ref(16, 16, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
    Image test = ref;
    test.at(2, 3).r = 0.75f;
    const std::string a = (dir / "a.exr").string(), b = (dir / "b.exr").string();
    writeImage(a, test);
    writeImage(b, ref);
    const std::string exe = SPLAT_EXE;
    const std::string out = (dir / "out.txt").string(), json = (dir / "m.json").string(),
                      heat = (dir / "h.png").string();
    const std::string cmd = "\"" + exe + "\" compare \"" + a + "\" \"" + b + "\" --heatmap \"" +
                            heat + "\" --json \"" + json + "\" > \"" + out + "\" 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    std::ifstream in(json);
    const nlohmann::json j = nlohmann::json::parse(in);
    CHECK(j["max_abs"].get<double>() == Approx(0.25).epsilon(1e-5));
    CHECK(j["rmse"].get<double>() == Approx(std::sqrt(0.0625 / (3.0 * 256))).epsilon(1e-5));
    CHECK(j["foreground_pixels"].get<int>() == 1);
    CHECK(fs::exists(heat));
    std::ifstream text(out);
    const std::string printed((std::istreambuf_iterator<char>(text)),
                              std::istreambuf_iterator<char>());
    CHECK(printed.find("rmse") != std::string::npos);
    CHECK(printed.find("psnr") != std::string::npos);

    // Bad input: a missing file and mismatched sizes exit non-zero with one line.
    const std::string missing = "\"" + exe + "\" compare \"" + (dir / "nope.exr").string() +
                                "\" \"" + b + "\" > \"" + out + "\" 2>&1";
    CHECK(std::system(missing.c_str()) != 0);
    writeImage((dir / "small.exr").string(), Image(8, 8));
    const std::string sizes = "\"" + exe + "\" compare \"" + (dir / "small.exr").string() +
                              "\" \"" + b + "\" > \"" + out + "\" 2>&1";
    CHECK(std::system(sizes.c_str()) != 0);
    std::ifstream err(out);
    std::string line;
    std::getline(err, line);
    CHECK(line.find("sizes differ") != std::string::npos);
    const std::string badScale =
        "\"" + exe + "\" compare \"" + a + "\" \"" + b + "\" --scale -1 > \"" + out + "\" 2>&1";
    CHECK(std::system(badScale.c_str()) != 0);
}
