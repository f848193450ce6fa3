// `splat compare A B [--heatmap OUT] [--scale S] [--json FILE]`: accuracy of test image A
// against reference image B (RGB; alpha ignored): RMSE, PSNR, max abs, mean abs over the
// foreground.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>

#include "commands.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/metrics.h"

namespace splat::cli {
namespace {

struct CompareArgs {
    std::string test, reference, heatmap, json;
    double scale = 0;
};

void writeJsonAtomically(const std::string& path, const nlohmann::json& j) {
    writeTextAtomic(path, j.dump(2) + "\n");
}

void run(const CompareArgs& a) {
    if (!std::isfinite(a.scale) || a.scale < 0)
        throw Error("compare: --scale must be >= 0 (0: the largest difference)");
    const Image test = readImage(a.test);
    const Image reference = readImage(a.reference);
    const ImageMetrics m = compareImages(test, reference);
    std::printf("test       %s\nreference  %s\nsize       %dx%d\n", a.test.c_str(),
                a.reference.c_str(), test.width, test.height);
    std::printf("rmse       %.6g\n", m.rmse);
    if (std::isfinite(m.psnr))
        std::printf("psnr       %.2f dB\n", m.psnr);
    else
        std::printf("psnr       inf (identical)\n");
    std::printf("max abs    %.6g\n", m.maxAbs);
    std::printf("mean abs   %.6g over %zu foreground pixels\n", m.meanAbsForeground,
                m.foregroundPixels);
    if (!a.heatmap.empty()) {
        writeHeatmap(a.heatmap, test, reference, a.scale);
        std::printf("heat map   %s (scale %.6g)\n", a.heatmap.c_str(),
                    a.scale > 0 ? a.scale : m.maxAbs);
    }
    if (!a.json.empty()) {
        nlohmann::json j;
        j["test"] = a.test;
        j["reference"] = a.reference;
        j["width"] = test.width;
        j["height"] = test.height;
        j["rmse"] = m.rmse;
        j["psnr"] = std::isfinite(m.psnr) ? nlohmann::json(m.psnr) : nlohmann::json(nullptr);
        j["max_abs"] = m.maxAbs;
        j["mean_abs_foreground"] = m.meanAbsForeground;
        j["foreground_pixels"] = m.foregroundPixels;
        writeJsonAtomically(a.json, j);
    }
}

}  // namespace

void registerCompare(CLI::App& app) {
    auto args = std::make_shared<CompareArgs>();
    CLI::App* cmd =
        app.add_subcommand("compare",
                           "Compare a test image A with a reference image B: RMSE, PSNR, max abs, "
                           "mean abs over the foreground");
    cmd->add_option("A", args->test, "Test image (.exr for linear values)")->required();
    cmd->add_option("B", args->reference, "Reference image")->required();
    cmd->add_option("--heatmap", args->heatmap, "Write |A - B| as an 'inferno' heat map");
    cmd->add_option("--scale", args->scale, "Heat map value shown at full scale (0: the max)");
    cmd->add_option("--json", args->json, "Write the metrics as JSON");
    cmd->callback([args] { run(*args); });
}

}  // namespace splat::cli
