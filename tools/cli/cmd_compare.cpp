// `splat compare A B [--heatmap OUT] [--scale S] [--json FILE]`: accuracy of test image A
// against reference image B (RGB; alpha ignored): RMSE, PSNR, max abs, mean abs over the
// foreground.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>

#include "commands.h"
#include "diagnostics.h"
#include "render_options.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/flip.h"
#include "splat/image_io.h"
#include "splat/metrics.h"

namespace splat::cli {
namespace {

namespace fs = std::filesystem;

struct CompareArgs {
    std::string test, reference, heatmap, json;
    std::vector<std::string> failAbove;
    double scale = 0, ppd = flipPixelsPerDegree(0.7, 0.7, 3840.0);
};

/// One --fail-above METRIC=VALUE.
struct Threshold {
    std::string metric;  ///< rmse | max | psnr-below | flip
    double value = 0;
};

Threshold parseThreshold(const std::string& text) {
    const std::size_t eq = text.find('=');
    Threshold t;
    t.metric = text.substr(0, eq);
    if (eq == std::string::npos ||
        (t.metric != "rmse" && t.metric != "max" && t.metric != "psnr-below" && t.metric != "flip"))
        throw UsageError("--fail-above '" + text +
                         "' must be METRIC=VALUE with METRIC rmse, max, psnr-below or flip");
    char* end = nullptr;
    const std::string v = text.substr(eq + 1);
    t.value = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(t.value) || t.value < 0)
        throw UsageError("--fail-above '" + text + "': the value must be a finite number >= 0");
    return t;
}

bool displayFile(const std::string& path) {
    const std::string e = lowerExtension(path);
    return e == ".png" || e == ".jpg" || e == ".jpeg" || e == ".gif";
}

bool sameFile(const std::string& a, const std::string& b) {
    std::error_code ec;
    if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
    return fs::absolute(a, ec).lexically_normal() == fs::absolute(b, ec).lexically_normal();
}

void run(const CompareArgs& a) {
    std::vector<Threshold> thresholds;
    asUsage([&] {
        if (!std::isfinite(a.scale) || a.scale < 0)
            throw Error("compare: --scale must be >= 0 (0: the largest difference)");
        if (!std::isfinite(a.ppd) || !(a.ppd > 0)) throw Error("compare: --ppd must be > 0");
        for (const std::string& f : a.failAbove) thresholds.push_back(parseThreshold(f));
        if (!a.heatmap.empty()) checkImageExtension(a.heatmap);
    });
    for (const std::string* out : {&a.heatmap, &a.json})
        if (!out->empty())
            for (const std::string* in : {&a.test, &a.reference})
                if (sameFile(*out, *in))
                    throw Error(*out + ": would overwrite the input image " + *in +
                                "; choose another output name");
    if (displayFile(a.test) != displayFile(a.reference))
        warn("compare: " + (displayFile(a.test) ? a.test : a.reference) +
             " holds display (sRGB-encoded 8-bit) values and " +
             (displayFile(a.test) ? a.reference : a.test) +
             " linear values; the metrics compare unlike quantities (compare .png with .png or "
             ".exr with .exr)");
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
    double flip = -1;
    if (std::any_of(thresholds.begin(), thresholds.end(),
                    [](const Threshold& t) { return t.metric == "flip"; })) {
        FlipOptions fo;
        fo.pixelsPerDegree = a.ppd;
        // Display files hold sRGB values: FLIP decodes them as its reference tool does.
        flip = displayFile(a.test) && displayFile(a.reference) ? flipMeanSrgb(test, reference, fo)
                                                               : flipMean(test, reference, fo);
        std::printf("flip       %.6g (mean LDR-FLIP, %.3g pixels per degree)\n", flip, a.ppd);
    }
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
        if (flip >= 0) j["flip"] = flip;
        writeTextAtomic(a.json, j.dump(2) + "\n");
    }
    std::string failed;
    for (const Threshold& t : thresholds) {
        double v = 0;
        bool over = false;
        if (t.metric == "rmse") v = m.rmse, over = !(m.rmse <= t.value);
        if (t.metric == "max") v = m.maxAbs, over = !(m.maxAbs <= t.value);
        if (t.metric == "flip") v = flip, over = !(flip <= t.value);
        if (t.metric == "psnr-below") v = m.psnr, over = m.psnr < t.value || std::isnan(m.psnr);
        if (over)
            failed += (failed.empty() ? "" : "; ") + t.metric + " " + CLI::detail::to_string(v) +
                      (t.metric == "psnr-below" ? " dB is below " : " is above ") +
                      CLI::detail::to_string(t.value);
    }
    if (!failed.empty()) throw Error("compare: " + failed + " (--fail-above)");
}

}  // namespace

void registerCompare(CLI::App& app) {
    auto args = std::make_shared<CompareArgs>();
    CLI::App* cmd =
        app.add_subcommand("compare",
                           "compare a test image A with a reference image B: RMSE, PSNR, max abs, "
                           "mean abs over the foreground; exit status 1 above --fail-above");
    cmd->add_option("A", args->test, "test image (.exr for linear values)")->required();
    cmd->add_option("B", args->reference, "reference image")->required();
    cmd->add_option("--fail-above", args->failAbove,
                    "METRIC=VALUE (repeatable): exit status 1 when rmse, max (largest absolute "
                    "difference) or flip (mean LDR-FLIP) is above VALUE, or the PSNR in dB is "
                    "below it (psnr-below)")
        ->group("Thresholds");
    cmd->add_option("--ppd", args->ppd, "LDR-FLIP pixels per degree (flip)")
        ->capture_default_str()
        ->group("Thresholds");
    cmd->add_option("--heatmap", args->heatmap, "write |A - B| as an 'inferno' heat map")
        ->group("Output");
    cmd->add_option("--scale", args->scale, "heat map value shown at full scale (0: the max)")
        ->capture_default_str()
        ->group("Output");
    cmd->add_option("--json", args->json, "write the metrics as JSON")->group("Output");
    cmd->footer(
        "Examples:\n"
        "  splat compare axis.exr reference.exr --heatmap diff.png\n"
        "  splat compare new.png golden.png --fail-above rmse=1e-3 --fail-above flip=0.05\n"
        "  splat compare a.exr b.exr --fail-above psnr-below=40 --json m.json");
    cmd->callback([args] { run(*args); });
}

}  // namespace splat::cli
