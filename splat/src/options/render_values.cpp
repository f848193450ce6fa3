// Rendering settings from option values (see splat/options.h): every value checked with the
// one-line message the command line, Python and scene files share.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "footprint/kernel.h"
#include "splat/options.h"
#include "splat/volume_io.h"

namespace splat {

namespace fs = std::filesystem;

namespace {

/// A number as the messages show it (the default stream formatting: 1e+06, 0.001).
std::string shown(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

void requireIn(double v, double lo, double hi, const std::string& what) {
    if (!std::isfinite(v) || v < lo || v > hi)
        throw OptionError(what + " must be a finite number between " + shown(lo) + " and " +
                          shown(hi) + " (got " + shown(v) + ")");
}

glm::dvec3 vec3Of(const std::vector<double>& v, std::size_t at) {
    return {v[at], v[at + 1], v[at + 2]};
}

void parseCamera(const OptionValues& v, RenderSettings& s) {
    const glm::ivec2 size = parseSize(v.text("size"), "--size");
    s.camera.width = size.x;
    s.camera.height = size.y;
    const double azimuth = v.real("azimuth"), elevation = v.real("elevation");
    requireIn(azimuth, -1e6, 1e6, "--azimuth");
    requireIn(elevation, -1e6, 1e6, "--elevation");
    s.camera.azimuthDeg = azimuth;
    s.camera.elevationDeg = elevation;
    const std::string& projection = v.text("projection");
    if (projection == "ortho" || projection == "orthographic")
        s.camera.projection = Projection::Orthographic;
    else if (projection == "perspective")
        s.camera.projection = Projection::Perspective;
    else
        throw OptionError("unknown projection '" + projection + "' (ortho or perspective)");
    const double pixelSize = v.real("pixel-size"), fov = v.real("fov"),
                 distance = v.real("distance");
    requireIn(pixelSize, 0, 1e12, "--pixel-size");
    requireIn(fov, 0.1, 170, "--fov");
    requireIn(distance, 0, 1e12, "--distance");
    s.camera.pixelSize = pixelSize;
    s.camera.fovDeg = fov;
    s.camera.distance = distance;
    const std::string &eye = v.text("eye"), &lookAt = v.text("look-at"), &up = v.text("up");
    if (eye.empty() && lookAt.empty() && up.empty()) return;
    auto vec3 = [](const std::string& text, const char* what) {
        const std::vector<double> p = parseNumbers(text, what);
        if (p.size() != 3) throw OptionError(std::string(what) + " needs X,Y,Z");
        for (double x : p) requireIn(x, -1e12, 1e12, what);
        return glm::dvec3(p[0], p[1], p[2]);
    };
    if (eye.empty()) throw OptionError("--look-at and --up need --eye (the free camera)");
    s.camera.lookAtSet = true;
    s.camera.eye = vec3(eye, "--eye");
    s.camera.lookAt = lookAt.empty() ? glm::dvec3(std::nan("")) : vec3(lookAt, "--look-at");
    if (!up.empty()) s.camera.upHint = vec3(up, "--up");
}

void parseKernelAndColours(const OptionValues& v, RenderSettings& s) {
    s.kernel = v.text("kernel");
    const double sigma = v.real("sigma"), radius = v.real("radius");
    requireIn(sigma, 0, 1e3, "--sigma");
    requireIn(radius, 0, 1e3, "--radius");
    s.kernelSigma = sigma;
    s.kernelRadius = radius;
    try {
        (void)footprint::Kernel::fromName(s.kernel, sigma, radius);  // names the kernels
    } catch (const std::exception& e) {
        throw OptionError(e.what());
    }
    const std::vector<double> bg = parseNumbers(v.text("background"), "--background");
    if (bg.size() != 3 && bg.size() != 4) throw OptionError("--background needs R,G,B or R,G,B,A");
    for (double c : bg) requireIn(c, 0, 1, "--background: every component");
    s.background =
        glm::vec4(float(bg[0]), float(bg[1]), float(bg[2]), bg.size() == 4 ? float(bg[3]) : 1.0f);
    const auto [iso, normalized] = parseIsoLevel(v.text("iso-level"));
    s.isoLevel = iso;
    s.isoNormalized = normalized;
    s.shading.enabled = v.flag("shade");
}

void parseLevelOfDetail(const std::string& lod, Quality& q) {
    if (lod == "auto") {
        q.lod = LevelOfDetail::automatic();
        return;
    }
    if (lod == "brick") {
        q.lod = LevelOfDetail::perBrick();
        return;
    }
    // One message for every value that is not a number: it names the words too.
    const std::string what =
        "--lod '" + lod + "' must be one number of pixels per voxel (0 = off), auto or brick";
    std::vector<double> l;
    try {
        l = parseNumbers(lod, "--lod");
    } catch (const Error&) {
        throw OptionError(what);
    }
    if (l.size() != 1) throw OptionError(what);
    requireIn(l[0], 0, 64, "--lod (pixels per voxel; 0 = off; or auto or brick)");
    q.lod = LevelOfDetail::threshold(l[0]);
}

void parseQuality(const OptionValues& v, RenderSettings& s) {
    Quality& q = s.quality;
    const double slab = v.real("slab");
    if (!std::isfinite(slab) || !(slab >= 1e-3) || slab > 1e4)
        throw OptionError("--slab: slab thickness must be between 0.001 and 10000 voxels (got " +
                          shown(slab) + ")");
    q.slab = slab;
    const double early = v.real("early-termination");
    if (!(early >= 0 && early < 1))
        throw OptionError("--early-termination: early termination threshold must be in [0, 1)");
    q.earlyTermination = early;
    const double warp = v.real("warp-tolerance");
    if (!(warp >= 0 && warp <= 1))
        throw OptionError("--warp-tolerance: the warp's error tolerance must be in [0, 1]");
    q.warpTolerance = warp;
    const long long threads = v.integer("threads"), tile = v.integer("tile-size");
    if (threads < 0 || threads > 1024)
        throw OptionError("--threads must be between 0 (all cores) and 1024");
    if (tile < 8 || tile > 32) throw OptionError("--tile-size must be between 8 and 32");
    s.threads = int(threads);
    q.tileSize = int(tile);
    parseLevelOfDetail(v.text("lod"), q);
    const double pixelFilter = v.real("pixel-filter");
    requireIn(pixelFilter, 0, 4, "--pixel-filter (sigma in pixels; 0 = point sampling)");
    q.pixelFilter = pixelFilter;
    try {
        q.ewa = parseEwa(v.text("ewa"));
    } catch (const Error& e) {
        throw OptionError(std::string("--ewa: ") + e.what());
    }
    const double refStep = v.real("ref-step"), refTolerance = v.real("ref-tolerance");
    if (refStep != 0) requireIn(refStep, 1e-3, 64, "--ref-step (voxels; 0 = automatic)");
    if (!std::isfinite(refTolerance) || !(refTolerance > 0) || refTolerance > 1)
        throw OptionError("--ref-tolerance must be a finite number in (0, 1]");
    q.referenceStep = refStep;
    q.referenceTolerance = refTolerance;
    if (!v.has("footprint-res")) return;  // the study-only knobs
    const long long footprint = v.integer("footprint-res"), radial = v.integer("slab-radial-res"),
                    depth = v.integer("slab-depth-res");
    if (footprint < 16 || footprint > 1048576)
        throw OptionError("--footprint-res must be between 16 and 1048576");
    if (radial < 4 || radial > 65536 || depth < 4 || depth > 65536)
        throw OptionError("--slab-radial-res and --slab-depth-res must be between 4 and 65536");
    const double tolerance = v.real("poly-tol");
    if (!std::isfinite(tolerance) || tolerance < 0)
        throw OptionError("--poly-tol must be a finite number >= 0");
    q.footprintResolution = int(footprint);
    q.slabRadialResolution = int(radial);
    q.slabDepthResolution = int(depth);
    q.polynomialTolerance = tolerance;
}

// An option given beside --quality wins: on the command line or as a Python keyword, or in a
// scene file with a value other than its default (written scenes hold every option).
bool givenBesidePreset(const OptionValues& v, std::string_view name) {
    return v.has(name) && v.given(name) && !(v.fromScene(name) && !v.differsFromDefault(name));
}

void applyQualityChoice(const OptionValues& v, RenderSettings& s) {
    QualityPreset preset = QualityPreset::Default;
    if (v.has("quality")) preset = parseQualityPreset(v.text("quality"));
    std::vector<std::string_view> keep;
    for (std::string_view name : qualityPresetOptions())
        if (givenBesidePreset(v, name)) keep.push_back(name);
    applyQualityPreset(s, preset, keep);
}

void parseShading(const OptionValues& v, RenderSettings& s) {
    Shading& sh = s.shading;
    const double ambient = v.real("ambient"), diffuse = v.real("diffuse"),
                 specular = v.real("specular"), shininess = v.real("shininess");
    sh.ambient = float(ambient);
    sh.diffuse = float(diffuse);
    sh.specular = float(specular);
    sh.shininess = float(shininess);
    for (double c : {ambient, diffuse, specular, shininess})
        if (!std::isfinite(c) || c < 0 || c > 1e4)
            throw OptionError(
                "--ambient, --diffuse, --specular and --shininess must be finite and >= 0");
    const std::string& light = v.text("light");
    if (light == "camera" || light == "headlight") {
        sh.headlight = true;
        return;
    }
    const std::vector<double> l = parseNumbers(light, "--light");
    if (l.size() != 3 || glm::length(vec3Of(l, 0)) == 0.0)
        throw OptionError("--light needs 'camera' or a non-zero direction X,Y,Z");
    sh.headlight = false;
    sh.light = glm::normalize(glm::vec3(vec3Of(l, 0)));
}

void parseEdgesAndClipping(const OptionValues& v, RenderSettings& s) {
    const std::string& edges = v.text("edges");
    if (!edges.empty()) {
        const std::vector<double> e = parseNumbers(edges, "--edges");
        if (e.empty() || e.size() > 2 || !(e[0] >= 0) || !std::isfinite(e[0]) ||
            (e.size() == 2 && (!(e[1] > 0) || !std::isfinite(e[1]))))
            throw OptionError("--edges needs GAIN >= 0 and optionally EXPONENT > 0");
        s.edges.gain = float(e[0]);
        if (e.size() == 2) s.edges.exponent = float(e[1]);
    }
    if (v.flag("iso-normalized")) s.isoNormalized = true;
    for (const std::string& text : v.list("clip-plane")) {
        const std::vector<double> p = parseNumbers(text, "--clip-plane");
        if (p.size() != 6 || glm::length(vec3Of(p, 3)) == 0.0)
            throw OptionError("--clip-plane needs X,Y,Z,NX,NY,NZ with a non-zero normal");
        s.clipping.planes.push_back({vec3Of(p, 0), glm::normalize(vec3Of(p, 3))});
    }
    const std::string& crop = v.text("crop");
    if (!crop.empty()) {
        const std::vector<double> c = parseNumbers(crop, "--crop");
        if (c.size() != 6) throw OptionError("--crop needs X0,Y0,Z0,X1,Y1,Z1");
        s.clipping.cropBox = true;
        s.clipping.boxMin = glm::min(vec3Of(c, 0), vec3Of(c, 3));
        s.clipping.boxMax = glm::max(vec3Of(c, 0), vec3Of(c, 3));
    }
}

void checkLabelsAndOutput(const OptionValues& v) {
    if (v.has("bit-depth")) {
        const long long bits = v.integer("bit-depth");
        if (bits != 8 && bits != 16) throw OptionError("--bit-depth must be 8 or 16");
    }
    if (v.text("label-colors").empty() &&
        (!v.text("label-volume").empty() || !v.text("labels").empty() ||
         !v.text("label-names").empty()))
        throw OptionError("--label-volume, --labels and --label-names need --label-colors FILE");
    const double opacity = v.real("label-opacity");
    if (!std::isfinite(opacity) || opacity < 0)
        throw OptionError("--label-opacity must be a finite number >= 0");
    const std::string& labels = v.text("labels");
    if (!labels.empty())
        for (double d : parseNumbers(labels, "--labels"))
            if (d != std::floor(d) || d < 0 || d > 65535)
                throw OptionError("--labels needs label numbers 0..65535, e.g. 37,38");
    if (v.has("window") && !v.text("window").empty()) {
        const std::vector<double> w = parseNumbers(v.text("window"), "--window");
        if (w.size() != 2 || !std::isfinite(w[0]) || !std::isfinite(w[1]) || !(w[1] > w[0]))
            throw OptionError("--window needs finite LOW,HIGH with HIGH > LOW");
    }
}

bool isPreset(const std::string& name) {
    for (const std::string& p : TransferFunction::presetNames())
        if (p == name) return true;
    return false;
}

// A transfer function given inline (a scene file's object, Python's TransferFunction) is read
// through a private temporary file, exactly as a file would be; errors name the scene key.
TransferFunction inlineTransfer(const OptionValues& v) {
    const std::string where = v.sceneFile + ": \"tf\"";
    std::string path = (fs::temp_directory_path() / "splat-tf-XXXXXX.json").string();
    const int fd = ::mkstemps(path.data(), 5);
    if (fd < 0) throw Error(where + ": cannot create a temporary file");
    const std::string& text = v.tfInline;
    const bool ok = ::write(fd, text.data(), text.size()) == ssize_t(text.size());
    ::close(fd);
    try {
        if (!ok) throw Error(path + ": write failed");
        TransferFunction tf = TransferFunction::fromJson(path);
        fs::remove(path);
        tf.name = "inline";
        return tf;
    } catch (const Error& e) {
        std::error_code ec;
        fs::remove(path, ec);
        std::string m = e.what();
        for (std::size_t at; (at = m.find(path)) != std::string::npos;)
            m.replace(at, path.size(), where);
        throw OptionError(m);
    }
}

// The flag given on the command line wins over a scene file's inline function.
bool tfFromFlag(const OptionValues& v) { return v.given("tf") && !v.fromScene("tf"); }

TransferFunction transferFrom(const OptionValues& v) {
    if (!v.tfInline.empty() && !tfFromFlag(v)) return inlineTransfer(v);
    // FILE.json, or FILE.json#Name for one preset of a ParaView file holding several.
    const std::string& tf = v.text("tf");
    const std::string path = tf.substr(0, tf.find('#'));
    const bool file = path.size() > 5 && path.substr(path.size() - 5) == ".json";
    if (!file && !isPreset(tf)) {
        try {
            TransferFunction::preset(tf);  // names the presets
        } catch (const Error& e) {
            throw OptionError(e.what());
        }
    }
    return TransferFunction::load(tf);
}

// After the transfer function is loaded: --tf-rescale, and the mode a preset carries (an
// explicit mode wins, with a warning when they disagree).
void applyTransferChoice(const OptionValues& v, RenderSettings& s, const WarnFn& warn) {
    const bool rescale = v.flag("tf-rescale");
    if (rescale && s.transfer.normalized)
        warn("--tf-rescale: transfer function '" + s.transfer.name +
             "' is already on the volume's normalized range; ignored");
    if (rescale) s.transfer = s.transfer.rescaledToData();
    // A preset that carries its mode: it applies unless a mode was chosen explicitly (--mode,
    // or a non-default mode from a scene file).
    std::string modeWarning;
    const bool explicitMode = v.given("mode") || s.mode != RenderMode::Dvr;
    s.mode = modeFor(s.transfer, s.mode, explicitMode, &modeWarning);
    if (!modeWarning.empty()) warn(modeWarning);
}

// Reads the files the options name (label tables and volumes).
void loadTechniqueFiles(const OptionValues& v, RenderSettings& s, const WarnFn& warn) {
    const std::string& colours = v.text("label-colors");
    if (colours.empty()) return;
    s.labels = Labels::load(colours, v.text("label-names"), float(v.real("label-opacity")));
    const std::string& labels = v.text("labels");
    if (!labels.empty())
        for (double d : parseNumbers(labels, "--labels")) s.labels.selection.push_back(int(d));
    const std::string& labelVolume = v.text("label-volume");
    if (!labelVolume.empty()) {
        auto volume = std::make_shared<const Volume>(loadVolume(labelVolume));
        if (!volume->note.empty()) warn(labelVolume + ": " + volume->note);
        s.labels.volume = volume;
    }
}

}  // namespace

glm::ivec2 parseSize(const std::string& text, const std::string& what) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    std::istringstream in(text);
    if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> extra))
        throw OptionError(what + " '" + text + "' must look like 512x512");
    if (w < 1 || h < 1 || w > 32768 || h > 32768)
        throw OptionError(what + " '" + text + "' must be between 1 and 32768 per side");
    return {w, h};
}

std::pair<double, bool> parseIsoLevel(const std::string& text) {
    std::string t = text;
    const bool normalized = !t.empty() && (t.back() == 'n' || t.back() == 'N');
    if (normalized) t.pop_back();
    char* end = nullptr;
    const double v = t.empty() ? NAN : std::strtod(t.c_str(), &end);
    if (t.empty() || *end != '\0' || !std::isfinite(v))
        throw OptionError("--iso-level '" + text +
                          "' must be a finite number (absolute) or a fraction of the volume's "
                          "range ending in n (e.g. 0.4n)");
    return {v, normalized};
}

std::vector<double> parseNumbers(const std::string& text, const std::string& what) {
    std::vector<double> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        try {
            std::size_t used = 0;
            v.push_back(std::stod(item, &used));
            if (used != item.size() || !std::isfinite(v.back())) throw std::invalid_argument(item);
        } catch (const std::exception&) {
            throw OptionError(what + " '" + text + "' must be comma-separated finite numbers");
        }
    }
    return v;
}

RenderSettings parseRenderOptions(const OptionValues& v) {
    RenderSettings s;
    try {
        s.renderer = parseRenderer(v.text("renderer"));
        s.mode = parseMode(v.text("mode"));
        s.order = parseOrder(v.text("order"));
        s.classification = parseClassification(v.text("classify"));
    } catch (const OptionError&) {
        throw;
    } catch (const Error& e) {
        throw OptionError(e.what());
    }
    parseCamera(v, s);
    parseKernelAndColours(v, s);
    parseQuality(v, s);
    applyQualityChoice(v, s);
    parseShading(v, s);
    parseEdgesAndClipping(v, s);
    checkLabelsAndOutput(v);
    return s;
}

void applyOption(RenderSettings& s, std::string_view name, const std::string& text) {
    OptionValues v(kRenderOptions | kStudyOnlyOptions);
    v.set(name, text);
    const RenderSettings p = parseRenderOptions(v);
    Quality& q = s.quality;
    const Quality& pq = p.quality;
    if (name == "renderer")
        s.renderer = p.renderer;
    else if (name == "mode")
        s.mode = p.mode;
    else if (name == "order")
        s.order = p.order;
    else if (name == "classify")
        s.classification = p.classification;
    else if (name == "size") {
        s.camera.width = p.camera.width;
        s.camera.height = p.camera.height;
    } else if (name == "kernel")
        s.kernel = p.kernel;
    else if (name == "sigma")
        s.kernelSigma = p.kernelSigma;
    else if (name == "radius")
        s.kernelRadius = p.kernelRadius;
    else if (name == "quality")
        applyQualityPreset(s, parseQualityPreset(text));
    else if (name == "slab")
        q.slab = pq.slab;
    else if (name == "early-termination")
        q.earlyTermination = pq.earlyTermination;
    else if (name == "tile-size")
        q.tileSize = pq.tileSize;
    else if (name == "warp-tolerance")
        q.warpTolerance = pq.warpTolerance;
    else if (name == "lod")
        q.lod = pq.lod;
    else if (name == "ewa")
        q.ewa = pq.ewa;
    else if (name == "pixel-filter")
        q.pixelFilter = pq.pixelFilter;
    else if (name == "ref-step")
        q.referenceStep = pq.referenceStep;
    else if (name == "ref-tolerance")
        q.referenceTolerance = pq.referenceTolerance;
    else if (name == "footprint-res")
        q.footprintResolution = pq.footprintResolution;
    else if (name == "slab-radial-res")
        q.slabRadialResolution = pq.slabRadialResolution;
    else if (name == "slab-depth-res")
        q.slabDepthResolution = pq.slabDepthResolution;
    else if (name == "poly-tol")
        q.polynomialTolerance = pq.polynomialTolerance;
    else
        throw OptionError("--" + std::string(name) + " cannot be set on its own");
}

void dropIgnoredOptions(OptionValues& v, const RenderSettings& s, const RenderUse& use,
                        const WarnFn& warn) {
    for (const OptionSpec* spec : v.specs()) {
        if (!spec->ignored) continue;
        std::istringstream reasons(spec->ignored(s, use, v));
        for (std::string why; std::getline(reasons, why);) {
            if (!v.given(spec->name) ||
                (v.fromScene(spec->name) && !v.differsFromDefault(spec->name)))
                break;
            warn(why + "; ignored");
            v.reset(spec->name);
        }
    }
}

RenderSettings renderSettingsFrom(OptionValues& v, const RenderUse& use, const WarnFn& warn) {
    RenderSettings s = parseRenderOptions(v);
    // The transfer function first: a preset may carry the mode, which decides what applies.
    s.transfer = transferFrom(v);
    applyTransferChoice(v, s, warn);
    const TransferFunction transfer = s.transfer;
    const RenderMode mode = s.mode;
    dropIgnoredOptions(v, s, use, warn);
    s = parseRenderOptions(v);
    s.transfer = transfer;
    s.mode = mode;
    loadTechniqueFiles(v, s, warn);
    return s;
}

RenderSettings withFreeCameraTarget(RenderSettings s, const Volume& volume) {
    if (s.camera.lookAtSet && std::isnan(s.camera.lookAt.x))
        s.camera.lookAt = volume.direction * volume.center();  // world
    return s;
}

RenderSettings withDataDefaults(const OptionValues& v, RenderSettings s, const Volume& volume,
                                const std::function<void(const std::string&)>& note) {
    const bool chosen = !v.tfInline.empty() || v.given("tf");
    if (chosen || s.mode != RenderMode::Dvr || s.labels.enabled || !looksLikeHounsfield(volume))
        return withFreeCameraTarget(s, volume);
    s.transfer = TransferFunction::preset("ct-hu");
    char background[32];
    std::snprintf(background, sizeof background, "%g", double(volume.background));
    if (note)
        note("CT in Hounsfield units (background " + std::string(background) + ", " +
             volume.backgroundSource + "): transfer function ct-hu (choose another with --tf)");
    return withFreeCameraTarget(s, volume);
}

}  // namespace splat
