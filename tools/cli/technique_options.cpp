// The classic techniques' options (see technique_options.h).
#include "technique_options.h"

#include <cstdio>
#include <sstream>

#include "splat/error.h"
#include "splat/volume_io.h"

namespace splat::cli {

namespace {

bool given(const TechniqueArgs& a, const std::string& flag) {
    const CLI::Option* o = a.cmd ? a.cmd->get_option_no_throw(flag) : nullptr;
    return o && o->count() > 0;
}

void warn(const std::string& line) { std::fprintf(stderr, "splat: warning: %s\n", line.c_str()); }

glm::dvec3 vec3Of(const std::vector<double>& v, std::size_t at) {
    return {v[at], v[at + 1], v[at + 2]};
}

}  // namespace

std::vector<double> parseNumbers(const std::string& text, const std::string& what) {
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

void addTechniqueOptions(CLI::App& cmd, TechniqueArgs& a) {
    a.cmd = &cmd;
    const std::string g = "Techniques";
    cmd.add_option("--ambient", a.ambient, "shading: ambient coefficient")
        ->capture_default_str()
        ->group(g);
    cmd.add_option("--diffuse", a.diffuse, "shading: diffuse coefficient")
        ->capture_default_str()
        ->group(g);
    cmd.add_option("--specular", a.specular, "shading: specular coefficient")
        ->capture_default_str()
        ->group(g);
    cmd.add_option("--shininess", a.shininess, "shading: Blinn-Phong exponent")
        ->capture_default_str()
        ->group(g);
    cmd.add_option("--light", a.light,
                   "shading light: camera (headlight) or X,Y,Z world direction towards it")
        ->capture_default_str()
        ->group(g);
    cmd.add_option("--edges", a.edges,
                   "edge enhancement GAIN[,EXPONENT]: opacity x (1 + GAIN ((|grad|/max)^EXP - 1))")
        ->group(g);
    cmd.add_flag("--iso-normalized", a.isoNormalized,
                 "--iso-level is a fraction of the volume's [min, max] (like the presets)")
        ->group(g);
    cmd.add_option("--clip-plane", a.clipPlanes,
                   "cut plane X,Y,Z,NX,NY,NZ (world): removes the side the normal points to; "
                   "repeatable")
        ->group(g);
    cmd.add_option("--crop", a.crop, "crop box X0,Y0,Z0,X1,Y1,Z1 (world units)")->group(g);
    cmd.add_option("--label-volume", a.labelVolume,
                   "segmentation label volume on VOLUME's grid (VOLUME is the intensity)")
        ->group(g);
    cmd.add_option("--label-colors", a.labelColors,
                   "label colours: FILE.lut (256 x RGB, mricron) or FILE.json; without "
                   "--label-volume, VOLUME itself holds the labels")
        ->group(g);
    cmd.add_option("--label-names", a.labelNames, "label names: FILE.txt (index name per line)")
        ->group(g);
    cmd.add_option("--labels", a.labels, "show only these labels, e.g. 37,38")->group(g);
    cmd.add_option("--label-opacity", a.labelOpacity,
                   "opacity of the labels per unit distance (tables without their own)")
        ->capture_default_str()
        ->group(g);
    cmd.add_flag("--tf-rescale", a.tfRescale,
                 "stretch the transfer function's first..last control values over the "
                 "volume's [min, max] (ParaView's 'rescale to data range')")
        ->group(g);
    cmd.add_option("--bit-depth", a.bitDepth, "PNG bits per channel: 8 or 16")
        ->capture_default_str()
        ->group(g);
    cmd.add_flag("--alpha", a.alpha, "PNG with alpha (transparent background)")->group(g);
}

bool applyTechniqueSceneKey(const std::string& key, const nlohmann::json& value, TechniqueArgs& a) {
    auto str = [&](std::string& out) {
        if (!given(a, "--" + key)) out = value.get<std::string>();
        return true;
    };
    auto num = [&](double& out) {
        if (!given(a, "--" + key)) out = value.get<double>();
        return true;
    };
    if (key == "ambient") return num(a.ambient);
    if (key == "diffuse") return num(a.diffuse);
    if (key == "specular") return num(a.specular);
    if (key == "shininess") return num(a.shininess);
    if (key == "light") return str(a.light);
    if (key == "edges") return str(a.edges);
    if (key == "crop") return str(a.crop);
    if (key == "label-volume") return str(a.labelVolume);
    if (key == "label-colors") return str(a.labelColors);
    if (key == "label-names") return str(a.labelNames);
    if (key == "labels") return str(a.labels);
    if (key == "label-opacity") return num(a.labelOpacity);
    if (key == "iso-normalized") {
        if (!given(a, "--iso-normalized")) a.isoNormalized = value.get<bool>();
        return true;
    }
    if (key == "tf-rescale") {
        if (!given(a, "--tf-rescale")) a.tfRescale = value.get<bool>();
        return true;
    }
    if (key == "alpha") {
        if (!given(a, "--alpha")) a.alpha = value.get<bool>();
        return true;
    }
    if (key == "bit-depth") {
        if (!given(a, "--bit-depth")) a.bitDepth = value.get<int>();
        return true;
    }
    if (key == "clip-plane" || key == "clip-planes") {
        if (given(a, "--clip-plane")) return true;
        a.clipPlanes.clear();
        if (value.is_string()) {
            a.clipPlanes.push_back(value.get<std::string>());
        } else {
            for (const auto& p : value) a.clipPlanes.push_back(p.get<std::string>());
        }
        return true;
    }
    return false;
}

void applyTechniqueArgs(const TechniqueArgs& a, RenderSettings& s) {
    if (a.tfRescale) s.transfer = s.transfer.rescaledToData();
    // A preset that carries its mode: it applies unless a mode was chosen explicitly (--mode,
    // or a non-default mode from a scene file); an explicit mode that disagrees wins, with a
    // warning.
    if (s.transfer.mode && *s.transfer.mode != s.mode) {
        if (given(a, "--mode") || s.mode != RenderMode::Dvr)
            warn(std::string("--mode ") + toString(s.mode) + " overrides the mode " +
                 toString(*s.transfer.mode) + " of transfer function '" + s.transfer.name + "'");
        else
            s.mode = *s.transfer.mode;
    }
    Shading& sh = s.shading;
    sh.ambient = float(a.ambient);
    sh.diffuse = float(a.diffuse);
    sh.specular = float(a.specular);
    sh.shininess = float(a.shininess);
    if (!(a.ambient >= 0 && a.diffuse >= 0 && a.specular >= 0 && a.shininess >= 0))
        throw Error("--ambient, --diffuse, --specular and --shininess must be >= 0");
    if (a.light == "camera" || a.light == "headlight") {
        sh.headlight = true;
    } else {
        const std::vector<double> l = parseNumbers(a.light, "--light");
        if (l.size() != 3 || glm::length(vec3Of(l, 0)) == 0.0)
            throw Error("--light needs 'camera' or a non-zero direction X,Y,Z");
        sh.headlight = false;
        sh.light = glm::normalize(glm::vec3(vec3Of(l, 0)));
    }
    if (!a.edges.empty()) {
        const std::vector<double> e = parseNumbers(a.edges, "--edges");
        if (e.empty() || e.size() > 2 || !(e[0] >= 0) || (e.size() == 2 && !(e[1] > 0)))
            throw Error("--edges needs GAIN >= 0 and optionally EXPONENT > 0");
        s.edges.gain = float(e[0]);
        if (e.size() == 2) s.edges.exponent = float(e[1]);
    }
    s.isoNormalized = a.isoNormalized;
    for (const std::string& text : a.clipPlanes) {
        const std::vector<double> p = parseNumbers(text, "--clip-plane");
        if (p.size() != 6 || glm::length(vec3Of(p, 3)) == 0.0)
            throw Error("--clip-plane needs X,Y,Z,NX,NY,NZ with a non-zero normal");
        s.clipping.planes.push_back({vec3Of(p, 0), glm::normalize(vec3Of(p, 3))});
    }
    if (!a.crop.empty()) {
        const std::vector<double> c = parseNumbers(a.crop, "--crop");
        if (c.size() != 6) throw Error("--crop needs X0,Y0,Z0,X1,Y1,Z1");
        s.clipping.cropBox = true;
        s.clipping.boxMin = glm::min(vec3Of(c, 0), vec3Of(c, 3));
        s.clipping.boxMax = glm::max(vec3Of(c, 0), vec3Of(c, 3));
    }
    if (a.bitDepth != 8 && a.bitDepth != 16) throw Error("--bit-depth must be 8 or 16");
    if (!a.labelColors.empty()) {
        s.labels = Labels::load(a.labelColors, a.labelNames, float(a.labelOpacity));
        if (!a.labels.empty())
            for (double d : parseNumbers(a.labels, "--labels"))
                s.labels.selection.push_back(int(d));
        if (!a.labelVolume.empty())
            s.labels.volume = std::make_shared<const Volume>(loadVolume(a.labelVolume));
    } else if (!a.labelVolume.empty() || !a.labels.empty() || !a.labelNames.empty()) {
        throw Error("--label-volume, --labels and --label-names need --label-colors FILE");
    }

    // Never silence: every option that does not apply gets a warning line.
    for (const std::string& line : inapplicableSettings(s)) warn(line);
    const bool shadingFlags = given(a, "--ambient") || given(a, "--diffuse") ||
                              given(a, "--specular") || given(a, "--shininess") ||
                              given(a, "--light");
    if (shadingFlags && !s.shading.enabled && s.mode == RenderMode::Dvr)
        warn("shading coefficients or --light given without --shade; ignored");
    if (shadingFlags && (s.mode == RenderMode::Xray || s.mode == RenderMode::Mip))
        warn(std::string("shading coefficients and --light do not apply to ") + toString(s.mode) +
             "; ignored");
    if (given(a, "--iso-level") && s.mode != RenderMode::Iso)
        warn(std::string("--iso-level applies to iso mode only; ignored in ") + toString(s.mode));
    if (a.isoNormalized && s.mode != RenderMode::Iso)
        warn(std::string("--iso-normalized applies to iso mode only; ignored in ") +
             toString(s.mode));
}

void applyTechniqueOutput(const TechniqueArgs& a, WriteOptions& o) {
    o.bitDepth = a.bitDepth;
    o.alpha = a.alpha;
}

}  // namespace splat::cli
