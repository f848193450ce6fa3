// Shared rendering options (see render_options.h).
#include "render_options.h"

#include <tuple>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "diagnostics.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/error.h"

namespace splat::cli {

namespace fs = std::filesystem;

void addRenderOptions(CLI::App& cmd, RenderArgs& a, bool imageOutput) {
    a.cmd = &cmd;
    const std::string cls = "Classification", cam = "Camera", ren = "Renderer", q = "Quality";
    addOption(cmd, "--mode", a.mode, "dvr | mip | xray | iso", cls);
    addOption(cmd, "--classify", a.classify,
              "pre | post: classification before or after reconstruction (dvr, iso)", cls);
    addOption(cmd, "--tf", a.tf,
              "transfer function: preset (ct-bone, ct-soft, mri-head, gray-ramp) or FILE.json "
              "(a scene file may hold it inline as an object)",
              cls, PathKind::Input);
    acceptObject(
        cmd, "tf", [&a](const nlohmann::json& j) { a.tfInline = j; }, [&a] { return a.tfInline; });
    addOption(cmd, "--iso-level", a.isoLevel,
              "iso: level of the density, absolute (120) or a fraction of the volume's "
              "[min, max] ending in n (0.4n)",
              cls);
    addOption(cmd, "--size", a.size, "image size WxH", cam);
    addOption(cmd, "--azimuth", a.azimuth, "camera azimuth, degrees", cam);
    addOption(cmd, "--elevation", a.elevation, "camera elevation, degrees", cam);
    addOption(cmd, "--projection", a.projection, "ortho | perspective", cam);
    addOption(cmd, "--pixel-size", a.pixelSize, "world units per pixel (0 = fit the volume)", cam);
    addOption(cmd, "--fov", a.fov, "perspective: vertical field of view, degrees", cam);
    addOption(cmd, "--distance", a.distance,
              "perspective: eye distance from the volume centre, world units (0 = fit)", cam);
    addOption(cmd, "--eye", a.eye,
              "free camera: eye position X,Y,Z (world; with --look-at, replaces the orbit)", cam);
    addOption(cmd, "--look-at", a.lookAt,
              "free camera: the point X,Y,Z at the image centre (default: the volume centre)",
              cam);
    addOption(cmd, "--up", a.up, "free camera: up vector X,Y,Z (default 0,0,1)", cam);
    addOption(cmd, "--renderer", a.renderer,
              "axis (axis-aligned sheets) | sheet (image-aligned slabs) | reference (ray caster)",
              ren);
    addOption(cmd, "--order", a.order, "dvr: ftb (front-to-back) | btf (back-to-front)", ren);
    addOption(cmd, "--kernel", a.kernel, "reconstruction kernel: gaussian | bspline", ren);
    addOption(cmd, "--sigma", a.sigma, "Gaussian sigma in voxels (0 = the kernel's default)", ren);
    addOption(cmd, "--radius", a.radius, "kernel radius in voxels (0 = the kernel's default)", ren);
    addOption(cmd, "--background", a.background, "background R,G,B[,A] in [0, 1]", ren);
    addFlag(cmd, "--shade", a.shade, "Blinn-Phong shading from the density gradient (dvr, iso)",
            ren);
    addOption(cmd, "--slab", a.slab, "sheet renderer: slab thickness, voxels", q);
    addOption(cmd, "--early-termination", a.earlyTermination,
              "splatters, front-to-back: stop when opacity >= 1 - EPS (0 = off)", q);
    addOption(cmd, "--ref-step", a.refStep, "reference renderer: first step, voxels (0: automatic, dvr 1 for the default kernel, else 0.25)", q);
    addOption(cmd, "--ref-tolerance", a.refTolerance,
              "reference renderer: step refinement tolerance", q);
    addOption(cmd, "--threads", a.threads, "worker threads (0 = all cores)", q);
    addOption(cmd, "--tile-size", a.tileSize, "splatters: screen tile edge in pixels (8..64)", q);
    addOption(cmd, "--lod", a.lod,
              "splatters: level of detail, pixels per voxel below which 2x2x2 voxels are "
              "merged into one splat of twice the size, repeatedly (0..64; 0 = off), or auto: "
              "the coarsest level whose merged voxels stay within the pixel filter (xray), or brick: "
              "that level per brick of 16^3 voxels where its dropped detail and seams stay "
              "small (xray)",
              q);
    addOption(cmd, "--pixel-filter", a.pixelFilter,
              "Gaussian pixel filter sigma in pixels (0..4): the reference supersamples and "
              "filters through it (0 = one ray at each pixel centre); the splatters' EWA "
              "low-pass (0 = 0.5)",
              q);
    addOption(cmd, "--ewa", a.ewa,
              "splatters: EWA resampling, footprints convolved with the pixel filter: off | on | "
              "auto (on in xray while a voxel covers fewer than 1 pixel); default auto",
              q);
    addTechniqueOptions(cmd, a.technique, imageOutput);
    if (imageOutput)
        addOption(cmd, "--window", a.window,
                  "mip/xray 8-bit output: display window LOW,HIGH (default: the data range, 0 included)", "Output");
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

std::pair<double, bool> parseIsoLevel(const std::string& text) {
    std::string t = text;
    const bool normalized = !t.empty() && (t.back() == 'n' || t.back() == 'N');
    if (normalized) t.pop_back();
    char* end = nullptr;
    const double v = t.empty() ? NAN : std::strtod(t.c_str(), &end);
    if (t.empty() || *end != '\0' || !std::isfinite(v))
        throw Error("--iso-level '" + text +
                    "' must be a finite number (absolute) or a fraction of the volume's range "
                    "ending in n (e.g. 0.4n)");
    return {v, normalized};
}

namespace {

void requireIn(double v, double lo, double hi, const std::string& what) {
    if (!std::isfinite(v) || v < lo || v > hi)
        throw Error(what + " must be a finite number between " + CLI::detail::to_string(lo) +
                    " and " + CLI::detail::to_string(hi) + " (got " + CLI::detail::to_string(v) +
                    ")");
}

// Every value that the command line reads, checked; no file is read here.
RenderSettings parseSettings(const RenderArgs& a) {
    RenderSettings s;
    s.renderer = parseRenderer(a.renderer);
    s.mode = parseMode(a.mode);
    s.order = parseOrder(a.order);
    s.classification = parseClassification(a.classify);
    const glm::ivec2 size = parseSize(a.size, "--size");
    s.camera.width = size.x;
    s.camera.height = size.y;
    requireIn(a.azimuth, -1e6, 1e6, "--azimuth");
    requireIn(a.elevation, -1e6, 1e6, "--elevation");
    s.camera.azimuthDeg = a.azimuth;
    s.camera.elevationDeg = a.elevation;
    if (a.projection == "ortho" || a.projection == "orthographic")
        s.camera.projection = Projection::Orthographic;
    else if (a.projection == "perspective")
        s.camera.projection = Projection::Perspective;
    else
        throw Error("unknown projection '" + a.projection + "' (ortho or perspective)");
    requireIn(a.pixelSize, 0, 1e12, "--pixel-size");
    requireIn(a.fov, 0.1, 170, "--fov");
    requireIn(a.distance, 0, 1e12, "--distance");
    s.camera.pixelSize = a.pixelSize;
    s.camera.fovDeg = a.fov;
    s.camera.distance = a.distance;
    if (!a.eye.empty() || !a.lookAt.empty() || !a.up.empty()) {
        auto vec3 = [](const std::string& text, const char* what) {
            const std::vector<double> v = parseNumbers(text, what);
            if (v.size() != 3) throw Error(std::string(what) + " needs X,Y,Z");
            for (double x : v) requireIn(x, -1e12, 1e12, what);
            return glm::dvec3(v[0], v[1], v[2]);
        };
        if (a.eye.empty()) throw Error("--look-at and --up need --eye (the free camera)");
        s.camera.lookAtSet = true;
        s.camera.eye = vec3(a.eye, "--eye");
        s.camera.lookAt = a.lookAt.empty() ? glm::dvec3(std::nan("")) : vec3(a.lookAt, "--look-at");
        if (!a.up.empty()) s.camera.upHint = vec3(a.up, "--up");
    }
    if (!std::isfinite(a.slab) || !(a.slab >= 1e-3) || a.slab > 1e4)
        throw Error("--slab: slab thickness must be between 0.001 and 10000 voxels (got " +
                    CLI::detail::to_string(a.slab) + ")");
    s.quality.slab = a.slab;
    s.kernel = a.kernel;
    requireIn(a.sigma, 0, 1e3, "--sigma");
    requireIn(a.radius, 0, 1e3, "--radius");
    s.kernelSigma = a.sigma;
    s.kernelRadius = a.radius;
    if (!(a.earlyTermination >= 0 && a.earlyTermination < 1))
        throw Error("--early-termination: early termination threshold must be in [0, 1)");
    s.quality.earlyTermination = a.earlyTermination;
    const std::vector<double> bg = parseNumbers(a.background, "--background");
    if (bg.size() != 3 && bg.size() != 4) throw Error("--background needs R,G,B or R,G,B,A");
    for (double c : bg) requireIn(c, 0, 1, "--background: every component");
    s.background =
        glm::vec4(float(bg[0]), float(bg[1]), float(bg[2]), bg.size() == 4 ? float(bg[3]) : 1.0f);
    const auto [iso, normalized] = parseIsoLevel(a.isoLevel);
    s.isoLevel = iso;
    s.isoNormalized = normalized;
    if (a.threads < 0 || a.threads > 1024)
        throw Error("--threads must be between 0 (all cores) and 1024");
    if (a.tileSize < 8 || a.tileSize > 64) throw Error("--tile-size must be between 8 and 64");
    s.threads = a.threads;
    s.quality.tileSize = a.tileSize;
    if (a.lod == "auto") {
        s.quality.lodAuto = true;
        s.quality.lod = 0;
    } else if (a.lod == "brick") {
        s.quality.lodBrick = true;
        s.quality.lod = 0;
    } else {
        // One message for every value that is not a number: it names the words too.
        const std::string what = "--lod '" + a.lod +
                                 "' must be one number of pixels per voxel (0 = off), auto or brick";
        std::vector<double> l;
        try {
            l = parseNumbers(a.lod, "--lod");
        } catch (const Error&) {
            throw Error(what);
        }
        if (l.size() != 1) throw Error(what);
        const double lod = l[0];
        requireIn(lod, 0, 64, "--lod (pixels per voxel; 0 = off; or auto or brick)");
        s.quality.lod = lod;
    }
    requireIn(a.pixelFilter, 0, 4, "--pixel-filter (sigma in pixels; 0 = point sampling)");
    s.quality.pixelFilter = a.pixelFilter;
    try {
        s.quality.ewa = parseEwa(a.ewa);
    } catch (const Error& e) {
        throw Error(std::string("--ewa: ") + e.what());
    }
    if (a.refStep != 0) requireIn(a.refStep, 1e-3, 64, "--ref-step (voxels; 0 = automatic)");
    if (!std::isfinite(a.refTolerance) || !(a.refTolerance > 0) || a.refTolerance > 1)
        throw Error("--ref-tolerance must be a finite number in (0, 1]");
    s.quality.referenceStep = a.refStep;
    s.quality.referenceTolerance = a.refTolerance;
    s.shading.enabled = a.shade;
    applyTechniqueArgs(a.technique, s);
    if (!a.window.empty()) {
        const std::vector<double> w = parseNumbers(a.window, "--window");
        if (w.size() != 2 || !std::isfinite(w[0]) || !std::isfinite(w[1]) || !(w[1] > w[0]))
            throw Error("--window needs finite LOW,HIGH with HIGH > LOW");
    }
    return s;
}

// A transfer function given inline in a scene file is read through a private temporary
// file, exactly as a file would be; errors name the scene key instead.
TransferFunction inlineTransfer(const RenderArgs& a) {
    const std::string where = sceneFileOf(*a.cmd) + ": \"tf\"";
    std::string path = (fs::temp_directory_path() / "splat-tf-XXXXXX.json").string();
    const int fd = ::mkstemps(path.data(), 5);
    if (fd < 0) throw Error(where + ": cannot create a temporary file");
    const std::string text = a.tfInline.dump();
    const bool ok = ::write(fd, text.data(), text.size()) == ssize_t(text.size());
    ::close(fd);
    try {
        if (!ok) throw Error(path + ": write failed");
        TransferFunction tf = TransferFunction::fromJson(path);
        std::filesystem::remove(path);
        tf.name = "inline";
        return tf;
    } catch (const Error& e) {
        std::error_code ec;
        std::filesystem::remove(path, ec);
        std::string m = e.what();
        for (std::size_t at; (at = m.find(path)) != std::string::npos;)
            m.replace(at, path.size(), where);
        throw UsageError(m);
    }
}

TransferFunction transferFromArgs(const RenderArgs& a) {
    if (!a.tfInline.is_null() && !(a.cmd && a.cmd->get_option("--tf")->count() > 0))
        return inlineTransfer(a);
    // FILE.json, or FILE.json#Name for one preset of a ParaView file holding several.
    const std::string path = a.tf.substr(0, a.tf.find('#'));
    const bool file = path.size() > 5 && path.substr(path.size() - 5) == ".json";
    if (!file && !isTransferPreset(a.tf))
        asUsage([&] { return TransferFunction::preset(a.tf); });  // names the presets
    return TransferFunction::load(a.tf);
}

}  // namespace

// --eye without --look-at looks at the volume centre (known once the volume is loaded).
RenderSettings withFreeCameraTarget(RenderSettings s, const Volume& volume) {
    if (s.camera.lookAtSet && std::isnan(s.camera.lookAt.x))
        s.camera.lookAt = volume.direction * volume.center();  // world
    return s;
}

RenderSettings withDataDefaults(const RenderArgs& a, RenderSettings s, const Volume& volume) {
    const bool chosen = !a.tfInline.is_null() || (a.cmd && a.cmd->get_option("--tf")->count() > 0);
    if (chosen || s.mode != RenderMode::Dvr || s.labels.enabled || !looksLikeHounsfield(volume))
        return withFreeCameraTarget(s, volume);
    s.transfer = TransferFunction::preset("ct-hu");
    std::fprintf(stderr,
                 "splat: CT in Hounsfield units (background %g, %s): transfer function ct-hu "
                 "(choose another with --tf)\n",
                 double(volume.background), volume.backgroundSource.c_str());
    return withFreeCameraTarget(s, volume);
}

RenderSettings settingsFromArgs(RenderArgs& a, const RenderUse& use) {
    RenderSettings s = asUsage([&] { return parseSettings(a); });
    // The transfer function first: a preset may carry the mode, which decides what applies.
    s.transfer = transferFromArgs(a);
    applyTransferChoice(a.technique, s);
    const TransferFunction transfer = s.transfer;
    const RenderMode mode = s.mode;
    dropIgnoredOptions(a, s, use);
    s = asUsage([&] { return parseSettings(a); });
    s.transfer = transfer;
    s.mode = mode;
    loadTechniqueFiles(a.technique, s);
    return s;
}

WriteOptions displayOptions(const RenderArgs& a, const RenderSettings& s, const Image& image) {
    WriteOptions o;
    applyTechniqueOutput(a.technique, o);
    o = withMetadata(o);
    if (s.mode == RenderMode::Dvr || s.mode == RenderMode::Iso) return o;
    o.mapping = DisplayMapping::Window;
    if (!a.window.empty()) {
        const std::vector<double> w = parseNumbers(a.window, "--window");
        o.windowLow = float(w[0]);
        o.windowHigh = float(w[1]);
    } else {
        std::tie(o.windowLow, o.windowHigh) = defaultWindow({&image});
    }
    return o;
}

}  // namespace splat::cli
