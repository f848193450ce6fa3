// The classic techniques' options (see technique_options.h).
#include "technique_options.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "diagnostics.h"
#include "scene_file.h"
#include "splat/error.h"
#include "splat/volume_io.h"

namespace splat::cli {

namespace {

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
            if (used != item.size() || !std::isfinite(v.back())) throw std::invalid_argument(item);
        } catch (const std::exception&) {
            throw Error(what + " '" + text + "' must be comma-separated finite numbers");
        }
    }
    return v;
}

void addTechniqueOptions(CLI::App& cmd, TechniqueArgs& a, bool imageOutput) {
    a.cmd = &cmd;
    const std::string cls = "Classification", ren = "Renderer";
    addFlag(cmd, "--iso-normalized", a.isoNormalized,
            "--iso-level is a fraction of the volume's [min, max] (same as the n suffix)", cls);
    addOption(cmd, "--edges", a.edges,
              "dvr edge enhancement GAIN[,EXPONENT]: opacity x (1 + GAIN ((|grad|/max)^EXP - 1))",
              cls);
    addOption(cmd, "--clip-plane", a.clipPlanes,
              "cut plane X,Y,Z,NX,NY,NZ (world): removes the side the normal points to; "
              "repeatable",
              cls);
    addOption(cmd, "--crop", a.crop, "crop box X0,Y0,Z0,X1,Y1,Z1 (world units)", cls);
    addOption(cmd, "--label-volume", a.labelVolume,
              "segmentation label volume on VOLUME's grid (VOLUME is the intensity)", cls,
              PathKind::Input);
    addOption(cmd, "--label-colors", a.labelColors,
              "label colours: FILE.lut (256 x RGB, mricron) or FILE.json; without "
              "--label-volume, VOLUME itself holds the labels",
              cls, PathKind::Input);
    addOption(cmd, "--label-names", a.labelNames, "label names: FILE.txt (index name per line)",
              cls, PathKind::Input);
    addOption(cmd, "--labels", a.labels, "show only these labels, e.g. 37,38", cls);
    addOption(cmd, "--label-opacity", a.labelOpacity,
              "opacity of the labels per unit distance (tables without their own)", cls);
    addFlag(cmd, "--tf-rescale", a.tfRescale,
            "stretch the transfer function's first..last control values over the volume's "
            "[min, max] (ParaView's 'rescale to data range')",
            cls);
    addOption(cmd, "--ambient", a.ambient, "shading: ambient coefficient", ren);
    addOption(cmd, "--diffuse", a.diffuse, "shading: diffuse coefficient", ren);
    addOption(cmd, "--specular", a.specular, "shading: specular coefficient", ren);
    addOption(cmd, "--shininess", a.shininess, "shading: Blinn-Phong exponent", ren);
    addOption(cmd, "--light", a.light,
              "shading light: camera (headlight) or X,Y,Z world direction towards it", ren);
    if (imageOutput) {
        addOption(cmd, "--bit-depth", a.bitDepth, "PNG bits per channel: 8 or 16", "Output");
        addFlag(cmd, "--alpha", a.alpha, "PNG with alpha (transparent background)", "Output");
    }
}

void applyTransferChoice(const TechniqueArgs& a, RenderSettings& s) {
    if (a.tfRescale && s.transfer.normalized)
        warn("--tf-rescale: transfer function '" + s.transfer.name +
             "' is already on the volume's normalized range; ignored");
    if (a.tfRescale) s.transfer = s.transfer.rescaledToData();
    // A preset that carries its mode: it applies unless a mode was chosen explicitly (--mode,
    // or a non-default mode from a scene file); an explicit mode that disagrees wins, with a
    // warning.
    std::string modeWarning;
    const bool explicitMode = (a.cmd && given(*a.cmd, "mode")) || s.mode != RenderMode::Dvr;
    s.mode = modeFor(s.transfer, s.mode, explicitMode, &modeWarning);
    if (!modeWarning.empty()) warn(modeWarning);
}

void applyTechniqueArgs(const TechniqueArgs& a, RenderSettings& s) {
    Shading& sh = s.shading;
    sh.ambient = float(a.ambient);
    sh.diffuse = float(a.diffuse);
    sh.specular = float(a.specular);
    sh.shininess = float(a.shininess);
    for (double c : {a.ambient, a.diffuse, a.specular, a.shininess})
        if (!std::isfinite(c) || c < 0 || c > 1e4)
            throw Error("--ambient, --diffuse, --specular and --shininess must be finite and >= 0");
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
        if (e.empty() || e.size() > 2 || !(e[0] >= 0) || !std::isfinite(e[0]) ||
            (e.size() == 2 && (!(e[1] > 0) || !std::isfinite(e[1]))))
            throw Error("--edges needs GAIN >= 0 and optionally EXPONENT > 0");
        s.edges.gain = float(e[0]);
        if (e.size() == 2) s.edges.exponent = float(e[1]);
    }
    if (a.isoNormalized) s.isoNormalized = true;
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
    if (a.labelColors.empty() &&
        (!a.labelVolume.empty() || !a.labels.empty() || !a.labelNames.empty()))
        throw Error("--label-volume, --labels and --label-names need --label-colors FILE");
    if (!std::isfinite(a.labelOpacity) || a.labelOpacity < 0)
        throw Error("--label-opacity must be a finite number >= 0");
    if (!a.labels.empty())
        for (double d : parseNumbers(a.labels, "--labels"))
            if (d != std::floor(d) || d < 0 || d > 65535)
                throw Error("--labels needs label numbers 0..65535, e.g. 37,38");
}

void loadTechniqueFiles(const TechniqueArgs& a, RenderSettings& s) {
    if (a.labelColors.empty()) return;
    s.labels = Labels::load(a.labelColors, a.labelNames, float(a.labelOpacity));
    if (!a.labels.empty())
        for (double d : parseNumbers(a.labels, "--labels")) s.labels.selection.push_back(int(d));
    if (!a.labelVolume.empty()) {
        auto labels = std::make_shared<const Volume>(loadVolume(a.labelVolume));
        if (!labels->note.empty()) warn(a.labelVolume + ": " + labels->note);
        s.labels.volume = labels;
    }
}

void applyTechniqueOutput(const TechniqueArgs& a, WriteOptions& o) {
    o.bitDepth = a.bitDepth;
    o.alpha = a.alpha;
}

}  // namespace splat::cli
