// The sweep options of `splat popping` (see popping_options.h).
#include "popping_options.h"

#include <cmath>
#include <sstream>

#include "diagnostics.h"
#include "scene_file.h"
#include "splat/error.h"

namespace splat::cli {

std::vector<RendererKind> parseRenderers(const std::string& text) {
    std::vector<RendererKind> out;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) out.push_back(parseRenderer(item));
    if (out.empty()) throw Error("--renderers is empty");
    return out;
}

void addPoppingOptions(CLI::App& cmd, PoppingArgs& a) {
    const std::string sw = "Sweep";
    addOption(cmd, "--from", a.from, "first angle of the sweep, degrees", sw);
    addOption(cmd, "--to", a.to, "last angle of the sweep (inclusive), degrees", sw);
    addOption(cmd, "--step", a.step, "angle step, degrees", sw);
    addOption(cmd, "--sweep", a.sweep, "the angle swept: azimuth or elevation", sw);
    addOption(cmd, "--path", a.path,
              "analyse a camera path instead of a sweep: JSON {\"keys\": [...]} as for rotate, "
              "interpolated over --frames views",
              sw, PathKind::Input);
    addOption(cmd, "--frames", a.frames, "views of --path (at least 3)", sw);
    addOption(cmd, "--renderers", a.renderers, "renderers to compare (reference: ground truth)",
              sw);
    addOption(cmd, "--refine", a.refine, "bisection levels around each event (0: none)", sw);
    addOption(cmd, "--threshold-k", a.k, "event threshold: median + K * MAD of the signal", sw);
    addOption(cmd, "--threshold-floor", a.floor, "... and at least FLOOR * median", sw);
    addOption(cmd, "--ppd", a.ppd, "LDR-FLIP pixels per degree", sw);
    addFlag(cmd, "--no-flip", a.noFlip, "skip the perceptual (LDR-FLIP) columns", sw);
    addOption(cmd, "--truth", a.truth,
              "the reference the splatters are judged against: point (one ray per pixel "
              "centre) | filtered (through the pixel filter, --pixel-filter or 0.5) | auto "
              "(filtered where the splatters' frames are: EWA on, e.g. xray below a pixel per "
              "voxel); default auto",
              sw);
}

std::vector<CameraParams> poppingViews(const PoppingArgs& a, const Sweep& sweep) {
    if (!a.path.empty()) return CameraPath::fromJson(a.path, sweep.base, a.frames).views;
    std::vector<CameraParams> views;
    for (double angle : sweep.angles()) views.push_back(sweep.camera(angle));
    return views;
}

void poppingFromArgs(const CLI::App& cmd, const PoppingArgs& a, const RenderSettings& settings,
                     Sweep& sweep, PoppingOptions& o) {
    asUsage([&] {
        if (a.sweep != "azimuth" && a.sweep != "elevation")
            throw Error("--sweep must be azimuth or elevation");
        sweep.angle = a.sweep == "azimuth" ? Sweep::Angle::Azimuth : Sweep::Angle::Elevation;
        sweep.from = a.from;
        sweep.to = a.to;
        sweep.step = a.step;
        sweep.base = settings.camera;
        if (!a.path.empty()) {
            for (const char* k : {"from", "to", "step", "sweep"})
                if (given(cmd, k))
                    throw Error(std::string("--") + k + " does not apply with --path");
            if (a.frames < 3 || a.frames > 100000)
                throw Error("--frames must be between 3 and 100000");
        } else {
            if (given(cmd, "frames")) throw Error("--frames applies only with --path");
            (void)sweep.angles();  // refuse a bad sweep before loading anything
        }
        o.renderers = parseRenderers(a.renderers);
        if (a.refine < 0 || a.refine > 60) throw Error("--refine must be between 0 and 60");
        for (double v : {a.k, a.floor, a.ppd})
            if (!std::isfinite(v) || v < 0)
                throw Error("--threshold-k, --threshold-floor and --ppd must be finite and >= 0");
        o.truth = parseTruth(a.truth);
    });
    o.refine = a.refine;
    o.madK = a.k;
    o.floorRatio = a.floor;
    o.pixelsPerDegree = a.ppd;
    o.flip = !a.noFlip;
}

}  // namespace splat::cli
