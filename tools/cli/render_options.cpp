// Shared rendering options (see render_options.h).
#include "render_options.h"

#include <tuple>

#include "diagnostics.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/error.h"

namespace splat::cli {

void addRenderOptions(CLI::App& cmd, RenderArgs& a, bool imageOutput) {
    a.cmd = &cmd;
    addTableOptions(cmd, a.values, kRenderOptions | (imageOutput ? kImageOptions : 0u));
    acceptObject(
        cmd, "tf",
        [&a](const nlohmann::json& j) { a.values.tfInline = j.dump(); },
        [&a] {
            return a.values.tfInline.empty() ? nlohmann::json()
                                             : nlohmann::json::parse(a.values.tfInline);
        });
    addSceneOptions(cmd);
}

void checkImageExtension(const std::string& path) {
    const std::string ext = lowerExtension(path);
    for (const char* ok : {".png", ".exr", ".tif", ".tiff", ".gif", ".jpg", ".jpeg"})
        if (ext == ok) return;
    throw UsageError(path + ": unsupported image type '" + ext + "' (use .png, .exr or .tif)");
}

void checkImageOutput(const std::string& path) {
    checkImageExtension(path);
    checkImagePath(path);
}

RenderSettings settingsFromArgs(RenderArgs& a, const RenderUse& use) {
    readGiven(*a.cmd, a.values);
    return asOptionUsage([&] { return renderSettingsFrom(a.values, use, warn); });
}

RenderSettings withDataDefaults(const RenderArgs& a, RenderSettings s, const Volume& volume) {
    return splat::withDataDefaults(a.values, std::move(s), volume, [](const std::string& line) {
        std::fprintf(stderr, "splat: %s\n", line.c_str());
    });
}

WriteOptions displayOptions(const RenderArgs& a, const RenderSettings& s, const Image& image) {
    WriteOptions o;
    o.bitDepth = int(a.values.integer("bit-depth"));
    o.alpha = a.values.flag("alpha");
    o = withMetadata(o);
    if (s.mode == RenderMode::Dvr || s.mode == RenderMode::Iso) return o;
    o.mapping = DisplayMapping::Window;
    const std::string& window = a.values.text("window");
    if (!window.empty()) {
        const std::vector<double> w = parseNumbers(window, "--window");
        o.windowLow = float(w[0]);
        o.windowHigh = float(w[1]);
    } else {
        std::tie(o.windowLow, o.windowHigh) = defaultWindow({&image});
    }
    return o;
}

}  // namespace splat::cli
