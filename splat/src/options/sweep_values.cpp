// popping's sweep from option values (see splat/options.h).
#include <cmath>
#include <sstream>

#include "splat/options.h"
#include "splat/sequence.h"

namespace splat {

std::vector<RendererKind> parseRenderers(const std::string& text) {
    std::vector<RendererKind> out;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) out.push_back(parseRenderer(item));
    if (out.empty()) throw OptionError("--renderers is empty");
    return out;
}

std::vector<CameraParams> poppingViews(const OptionValues& v, const Sweep& sweep) {
    const std::string& path = v.text("path");
    if (!path.empty())
        return CameraPath::fromJson(path, sweep.base, int(v.integer("frames"))).views;
    std::vector<CameraParams> views;
    for (double angle : sweep.angles()) views.push_back(sweep.camera(angle));
    return views;
}

void poppingFrom(const OptionValues& v, const RenderSettings& settings, Sweep& sweep,
                 PoppingOptions& o) {
    try {
        const std::string& swept = v.text("sweep");
        if (swept != "azimuth" && swept != "elevation")
            throw OptionError("--sweep must be azimuth or elevation");
        sweep.angle = swept == "azimuth" ? Sweep::Angle::Azimuth : Sweep::Angle::Elevation;
        sweep.from = v.real("from");
        sweep.to = v.real("to");
        sweep.step = v.real("step");
        sweep.base = settings.camera;
        const long long frames = v.integer("frames");
        if (!v.text("path").empty()) {
            for (const char* k : {"from", "to", "step", "sweep"})
                if (v.given(k))
                    throw OptionError(std::string("--") + k + " does not apply with --path");
            if (frames < 3 || frames > 100000)
                throw OptionError("--frames must be between 3 and 100000");
        } else {
            if (v.given("frames")) throw OptionError("--frames applies only with --path");
            (void)sweep.angles();  // refuse a bad sweep before loading anything
        }
        o.renderers = parseRenderers(v.text("renderers"));
        const long long refine = v.integer("refine");
        if (refine < 0 || refine > 60) throw OptionError("--refine must be between 0 and 60");
        const double k = v.real("threshold-k"), floor = v.real("threshold-floor"),
                     ppd = v.real("ppd");
        for (double x : {k, floor, ppd})
            if (!std::isfinite(x) || x < 0)
                throw OptionError(
                    "--threshold-k, --threshold-floor and --ppd must be finite and >= 0");
        o.truth = parseTruth(v.text("truth"));
        o.refine = int(refine);
        o.madK = k;
        o.floorRatio = floor;
        o.pixelsPerDegree = ppd;
        o.flip = !v.flag("no-flip");
        o.warpFlip = !v.flag("no-warp-flip");
    } catch (const OptionError&) {
        throw;
    } catch (const Error& e) {
        throw OptionError(e.what());
    }
}

}  // namespace splat
