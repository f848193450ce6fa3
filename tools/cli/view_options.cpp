// Options and output of the volume-viewing commands (see view_options.h).
#include "view_options.h"

#include <algorithm>
#include <cmath>

#include "diagnostics.h"
#include "scene_file.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/options.h"

namespace splat::cli {

void addViewOptions(CLI::App& cmd, ViewArgs& a) {
    constexpr unsigned V = kViewOptions;
    addTableOption(cmd, "kernel", a.kernel, V);
    addTableOption(cmd, "sigma", a.sigma, V);
    addTableOption(cmd, "radius", a.radius, V);
    addTableOption(cmd, "threads", a.threads, V);
    addTableOption(cmd, "window", a.window, V);
    addTableOption(cmd, "window-preset", a.windowPreset, V);
    addTableOption(cmd, "scale-bar", a.scaleBar, V);
    addTableOption(cmd, "bit-depth", a.bitDepth, V);
}

void checkViewArgs(const ViewArgs& a) {
    asUsage([&] {
        if (a.bitDepth != 8 && a.bitDepth != 16) throw Error("--bit-depth must be 8 or 16");
        if (!std::isfinite(a.sigma) || a.sigma < 0 || !std::isfinite(a.radius) || a.radius < 0)
            throw Error("--sigma and --radius must be finite and >= 0");
        if (a.threads < 0 || a.threads > 1024)
            throw Error("--threads must be between 0 (all cores) and 1024");
        if (!std::isfinite(a.scaleBar) || a.scaleBar < 0)
            throw Error("--scale-bar must be a finite length >= 0");
        if (!a.window.empty()) {
            const std::vector<double> w = parseNumbers(a.window, "--window");
            if (w.size() != 2 || !(w[1] > w[0])) throw Error("--window needs LO,HI with HI > LO");
        }
        const std::string& p = a.windowPreset;
        if (!p.empty() && p != "full" && p != "ct-brain" && p != "ct-soft" && p != "ct-bone" &&
            p != "ct-lung")
            throw Error("unknown window preset '" + p +
                        "' (full, ct-brain, ct-soft, ct-bone, ct-lung)");
        if (!a.window.empty() && !a.windowPreset.empty())
            warn("--window-preset does not apply with --window; ignored");
    });
}

glm::dvec3 parseVec3(const std::string& text, const std::string& what) {
    const std::vector<double> v = parseNumbers(text, what);
    if (v.size() != 3) throw Error(what + " '" + text + "' needs three numbers X,Y,Z");
    return {v[0], v[1], v[2]};
}

void writeView(const std::string& path, Image image, const ViewArgs& a, const Volume& volume,
               double pixelSize) {
    WriteOptions o = withMetadata({});
    o.mapping = DisplayMapping::Window;
    if (a.bitDepth != 8 && a.bitDepth != 16) throw Error("--bit-depth must be 8 or 16");
    o.bitDepth = a.bitDepth;
    if (!a.window.empty()) {
        const std::vector<double> w = parseNumbers(a.window, "--window");
        if (w.size() != 2 || !(w[1] > w[0])) throw Error("--window needs LO,HI with HI > LO");
        o.windowLow = float(w[0]);
        o.windowHigh = float(w[1]);
    } else {
        const std::string p = a.windowPreset.empty() ? "full" : a.windowPreset;
        double level, width;
        if (p == "full") {
            const VolumeStats st = volumeStats(volume, 1);
            level = 0.5 * (st.minValue + st.maxValue);
            width = std::max(1e-6, double(st.maxValue - st.minValue));
        } else if (p == "ct-brain") {
            level = 40, width = 80;
        } else if (p == "ct-soft") {
            level = 50, width = 400;
        } else if (p == "ct-bone") {
            level = 500, width = 2000;
        } else if (p == "ct-lung") {
            level = -600, width = 1500;
        } else {
            throw Error("unknown window preset '" + p +
                        "' (full, ct-brain, ct-soft, ct-bone, ct-lung)");
        }
        o.windowLow = float(level - 0.5 * width);
        o.windowHigh = float(level + 0.5 * width);
    }
    if (a.scaleBar > 0) {
        // A bar of scaleBar world units, 3 pixels high, 8 pixels from the bottom-left corner,
        // drawn at the window's top value (white), outlined in its bottom value.
        const int len = int(std::lround(a.scaleBar / pixelSize));
        const int x0 = 8, y1 = image.height - 8;
        for (int y = y1 - 4; y <= y1; ++y)
            for (int x = x0 - 1; x <= x0 + len; ++x) {
                if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
                const bool inner = y > y1 - 4 && y < y1 && x >= x0 && x < x0 + len;
                image.at(x, y) = glm::vec4(glm::vec3(inner ? o.windowHigh : o.windowLow), 1.0f);
            }
    }
    writeImage(path, image, o);
}

}  // namespace splat::cli
