// Shared rendering options and scene files (see render_options.h).
#include "render_options.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "splat/error.h"

namespace splat::cli {

void addRenderOptions(CLI::App& cmd, RenderArgs& a) {
    a.cmd = &cmd;
    cmd.add_option("--renderer", a.renderer, "axis | sheet | reference")->capture_default_str();
    cmd.add_option("--mode", a.mode, "dvr | mip | xray | iso")->capture_default_str();
    cmd.add_option("--order", a.order, "ftb (front-to-back) | btf (back-to-front)")
        ->capture_default_str();
    cmd.add_option("--classify", a.classify,
                   "pre | post (classification before or after reconstruction)")
        ->capture_default_str();
    cmd.add_option("--tf", a.tf,
                   "transfer function preset (ct-bone, ct-soft, mri-head, gray-ramp) or FILE.json")
        ->capture_default_str();
    cmd.add_option("--size", a.size, "image size WxH")->capture_default_str();
    cmd.add_option("--azimuth", a.azimuth, "camera azimuth, degrees")->capture_default_str();
    cmd.add_option("--elevation", a.elevation, "camera elevation, degrees")->capture_default_str();
    cmd.add_option("--projection", a.projection, "ortho | perspective")->capture_default_str();
    cmd.add_option("--pixel-size", a.pixelSize, "world units per pixel (0 = fit the volume)")
        ->capture_default_str();
    cmd.add_option("--fov", a.fov, "perspective vertical field of view, degrees")
        ->capture_default_str();
    cmd.add_option("--slab", a.slab, "image-aligned slab thickness, voxels")->capture_default_str();
    cmd.add_option("--kernel", a.kernel, "reconstruction kernel: gaussian | bspline")
        ->capture_default_str();
    cmd.add_option("--sigma", a.sigma, "Gaussian sigma in voxels (0 = default)")
        ->capture_default_str();
    cmd.add_option("--radius", a.radius, "kernel radius in voxels (0 = default)")
        ->capture_default_str();
    cmd.add_option("--early-termination", a.earlyTermination,
                   "front-to-back: stop when opacity >= 1 - EPS (0 = off)")
        ->capture_default_str();
    cmd.add_option("--background", a.background, "background R,G,B[,A] in [0, 1]")
        ->capture_default_str();
    cmd.add_option("--iso-level", a.isoLevel, "iso mode: level of the density")
        ->capture_default_str();
    cmd.add_option("--window", a.window, "mip/xray PNG display window LOW,HIGH (default 0,max)");
    cmd.add_option("--threads", a.threads, "worker threads (0 = all cores)")->capture_default_str();
    cmd.add_option("--tile-size", a.tileSize, "screen tile edge in pixels (8..64)")
        ->capture_default_str();
    cmd.add_option("--ref-step", a.refStep, "reference: initial step, voxels")
        ->capture_default_str();
    cmd.add_option("--ref-tolerance", a.refTolerance, "reference: step refinement tolerance")
        ->capture_default_str();
    cmd.add_flag("--shade", a.shade,
                 "headlight Phong shading from the density gradient (pre-classified dvr)");
    // Issue 12 (study branch): eye distance, so that views from inside the volume are possible.
    cmd.add_option("--distance", a.distance,
                   "perspective: eye distance from the volume centre, world units (0 = fit)")
        ->capture_default_str();
    cmd.add_option("--scene", a.scene,
                   "scene FILE.json holding any of these options (flags override it)");
    addTechniqueOptions(cmd, a.technique);
}

glm::ivec2 parseSize(const std::string& text, const std::string& what) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    std::istringstream in(text);
    if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> extra))
        throw Error(what + " '" + text + "' must look like 512x512");
    if (w < 1 || h < 1 || w > 32768 || h > 32768)
        throw Error(what + " '" + text + "' must be between 1 and 32768 per side");
    return {w, h};
}

namespace {

std::vector<double> parseList(const std::string& text, const std::string& what) {
    std::vector<double> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        try {
            std::size_t used = 0;
            v.push_back(std::stod(item, &used));
            if (used != item.size()) throw std::invalid_argument(item);
        } catch (const std::exception&) {
            throw Error(what + " '" + text + "' must be comma-separated numbers");
        }
    }
    return v;
}

// Reads the scene file into `a` for every key it has; keys use the flag names without
// dashes ("renderer", "pixel-size", ...).
RenderArgs withScene(const RenderArgs& given) {
    RenderArgs a = given;
    std::ifstream in(given.scene);
    if (!in) throw Error(given.scene + ": cannot open scene file");
    nlohmann::json j;
    try {
        in >> j;
    } catch (const std::exception& e) {
        throw Error(given.scene + ": not valid JSON (" + std::string(e.what()) + ")");
    }
    if (!j.is_object()) throw Error(given.scene + ": a scene file must be a JSON object");
    auto flagGiven = [&](const std::string& key) {
        const CLI::Option* o = given.cmd ? given.cmd->get_option_no_throw("--" + key) : nullptr;
        return o && o->count() > 0;
    };
    try {
        for (auto& [key, value] : j.items()) {
            if (flagGiven(key)) continue;
            if (key == "renderer")
                a.renderer = value.get<std::string>();
            else if (key == "mode")
                a.mode = value.get<std::string>();
            else if (key == "order")
                a.order = value.get<std::string>();
            else if (key == "classify")
                a.classify = value.get<std::string>();
            else if (key == "tf")
                a.tf = value.get<std::string>();
            else if (key == "size")
                a.size = value.get<std::string>();
            else if (key == "projection")
                a.projection = value.get<std::string>();
            else if (key == "kernel")
                a.kernel = value.get<std::string>();
            else if (key == "background")
                a.background = value.get<std::string>();
            else if (key == "window")
                a.window = value.get<std::string>();
            else if (key == "azimuth")
                a.azimuth = value.get<double>();
            else if (key == "elevation")
                a.elevation = value.get<double>();
            else if (key == "pixel-size")
                a.pixelSize = value.get<double>();
            else if (key == "fov")
                a.fov = value.get<double>();
            else if (key == "slab")
                a.slab = value.get<double>();
            else if (key == "sigma")
                a.sigma = value.get<double>();
            else if (key == "radius")
                a.radius = value.get<double>();
            else if (key == "early-termination")
                a.earlyTermination = value.get<double>();
            else if (key == "iso-level")
                a.isoLevel = value.get<double>();
            else if (key == "ref-step")
                a.refStep = value.get<double>();
            else if (key == "ref-tolerance")
                a.refTolerance = value.get<double>();
            else if (key == "threads")
                a.threads = value.get<int>();
            else if (key == "tile-size")
                a.tileSize = value.get<int>();
            else if (key == "shade")
                a.shade = value.get<bool>();
            else if (key == "distance")  // issue 12
                a.distance = value.get<double>();
            else if (!applyTechniqueSceneKey(key, value, a.technique))
                throw Error(given.scene + ": unknown scene key '" + key + "'");
        }
    } catch (const nlohmann::json::exception& e) {
        throw Error(given.scene + ": wrong value type (" + std::string(e.what()) + ")");
    }
    return a;
}

}  // namespace

RenderSettings settingsFromArgs(const RenderArgs& given) {
    const RenderArgs a = given.scene.empty() ? given : withScene(given);
    RenderSettings s;
    s.renderer = parseRenderer(a.renderer);
    s.mode = parseMode(a.mode);
    s.order = parseOrder(a.order);
    s.classification = parseClassification(a.classify);
    s.transfer = TransferFunction::load(a.tf);
    const glm::ivec2 size = parseSize(a.size, "--size");
    s.camera.width = size.x;
    s.camera.height = size.y;
    s.camera.azimuthDeg = a.azimuth;
    s.camera.elevationDeg = a.elevation;
    if (a.projection == "ortho" || a.projection == "orthographic")
        s.camera.projection = Projection::Orthographic;
    else if (a.projection == "perspective")
        s.camera.projection = Projection::Perspective;
    else
        throw Error("unknown projection '" + a.projection + "' (ortho or perspective)");
    s.camera.pixelSize = a.pixelSize;
    s.camera.fovDeg = a.fov;
    s.camera.distance = a.distance;  // issue 12
    s.quality.slab = a.slab;
    s.kernel = a.kernel;
    s.kernelSigma = a.sigma;
    s.kernelRadius = a.radius;
    s.quality.earlyTermination = a.earlyTermination;
    const std::vector<double> bg = parseList(a.background, "--background");
    if (bg.size() != 3 && bg.size() != 4) throw Error("--background needs R,G,B or R,G,B,A");
    s.background =
        glm::vec4(float(bg[0]), float(bg[1]), float(bg[2]), bg.size() == 4 ? float(bg[3]) : 1.0f);
    s.isoLevel = a.isoLevel;
    s.threads = a.threads;
    s.quality.tileSize = a.tileSize;
    s.quality.referenceStep = a.refStep;
    s.quality.referenceTolerance = a.refTolerance;
    s.shading.enabled = a.shade;
    applyTechniqueArgs(a.technique, s);
    return s;
}

WriteOptions displayOptions(const RenderArgs& a, const RenderSettings& s, const Image& image) {
    WriteOptions o;
    applyTechniqueOutput(a.technique, o);
    if (s.mode == RenderMode::Dvr || s.mode == RenderMode::Iso) return o;
    o.mapping = DisplayMapping::Window;
    if (!a.window.empty()) {
        const std::vector<double> w = parseList(a.window, "--window");
        if (w.size() != 2 || !(w[1] > w[0])) throw Error("--window needs LOW,HIGH with HIGH > LOW");
        o.windowLow = float(w[0]);
        o.windowHigh = float(w[1]);
    } else {
        float mx = 0.0f;
        for (const auto& p : image.pixels)
            if (std::isfinite(p.r)) mx = std::max(mx, p.r);
        o.windowLow = 0.0f;
        o.windowHigh = mx > 0.0f ? mx : 1.0f;
    }
    return o;
}

}  // namespace splat::cli
