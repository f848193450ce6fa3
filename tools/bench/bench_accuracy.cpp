// bench_accuracy: the splatters against the reference ray caster of the same model.
//
//   bench_accuracy [VOLUME] [TF] [--size N] [--mode dvr|mip|xray] [--classify pre|post]
//                  [--azimuths 0,30,45] [--elevation E] [--early-termination EPS]
//                  [--lod L|auto[,...]] [--supersample N] [--pixel-filter SIGMA] [--ewa]
//                  [--axis-only] [--truth auto|point|filtered]
//
// VOLUME defaults to synthetic:phantom:64, TF to ct-soft. For each azimuth renders the
// reference, the axis-aligned splatter and the image-aligned splatter with slabs of 1, 0.5
// and 0.25 voxels at N x N (default 256), and prints a markdown table of RMSE, PSNR and
// max abs difference against the reference, with milliseconds per frame (the Renderer is
// built once per configuration; the time is that of render() alone). The splatters use the
// default front-to-back early termination (1/256) unless --early-termination says otherwise.
// --lod L adds the axis-aligned and slab-1 image-aligned splatters at level of detail L
// (Quality::lod, a pixel threshold) and their level; --lod auto and --lod brick the same with
// those kinds of LevelOfDetail (docs/speed-vs-accuracy.md "Level of detail"); with --ewa also both with EWA
// on; a list (--lod 1,auto) adds each in turn. --axis-only leaves out the image-aligned rows.
// --supersample N renders the reference with N x N rays per pixel (at N times the size) and
// box-filters it: the pixel's area average rather than its centre's value.
//
// Where a voxel covers fewer than one pixel (or with --pixel-filter SIGMA, or --truth
// filtered), it also renders the pixel-filtered reference (Quality::pixelFilter: s x s rays
// per pixel through a Gaussian of SIGMA pixels, default 0.5, converged; docs/accuracy.md "Aliasing
// and EWA") and gives every row two sets of columns: RMSE against the point-sampled reference (one
// ray at each pixel centre, the columns above) and RMSE, PSNR and max abs against the filtered one.
// --truth point leaves the filtered reference out (it costs s^2 reference frames and more). The
// splatters' rows use the default EWA setting (Quality::ewa auto: on in xray below a pixel per
// voxel; the label says ", EWA" where it was on); --ewa adds the axis-aligned and slab-1
// image-aligned splatters with EWA off and with EWA on (low-pass SIGMA, or 0.5 pixels).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "splat/metrics.h"
#include "splat/render.h"
#include "splat/volume.h"
#include "splat/volume_io.h"

using namespace splat;

namespace {

struct Config {
    std::string label;
    RendererKind kind;
    double slab;
    double lod = 0;
    Ewa ewa = Ewa::Auto;
    bool lodAuto = false;
};

/// ": a + b + ... per level" where a frame mixed levels (--lod brick), else "".
std::string perLevel(const std::vector<std::size_t>& n) {
    if (std::count_if(n.begin(), n.end(), [](std::size_t c) { return c > 0; }) < 2) return "";
    std::string s = ": ";
    for (std::size_t l = 0; l < n.size(); ++l)
        s += (l ? " + " : "") + std::to_string(n[l]);
    return s + " per level";
}

std::vector<double> parseList(const std::string& s) {
    std::vector<double> out;
    std::stringstream in(s);
    std::string item;
    while (std::getline(in, item, ',')) out.push_back(std::stod(item));
    return out;
}

void usage() {
    std::fprintf(stderr,
                 "usage: bench_accuracy [VOLUME] [TF] [--size N] [--mode dvr|mip|xray] "
                 "[--classify pre|post] [--azimuths 0,30,45] [--elevation E] "
                 "[--early-termination EPS] [--lod L|auto[,...]] [--supersample N] "
                 "[--pixel-filter SIGMA] [--ewa] [--axis-only] [--truth auto|point|filtered]\n");
}

}  // namespace

int main(int argc, char** argv) {
    try {
        std::string volumeSpec = "synthetic:phantom:64", tf = "ct-soft", mode = "dvr",
                    classify = "pre", truth = "auto";
        int size = 256, supersample = 1;
        double earlyTermination = -1, elevation = 0, pixelFilter = 0;
        bool ewa = false, axisOnly = false;
        std::vector<std::string> lods;
        std::vector<double> azimuths = {0, 30, 45};
        std::vector<std::string> positional;
        for (int a = 1; a < argc; ++a) {
            const std::string arg = argv[a];
            auto value = [&]() -> std::string {
                if (a + 1 >= argc) throw std::runtime_error(arg + " needs a value");
                return argv[++a];
            };
            if (arg == "--size")
                size = std::stoi(value());
            else if (arg == "--mode")
                mode = value();
            else if (arg == "--classify")
                classify = value();
            else if (arg == "--azimuths")
                azimuths = parseList(value());
            else if (arg == "--early-termination")
                earlyTermination = std::stod(value());
            else if (arg == "--supersample")
                supersample = std::stoi(value());
            else if (arg == "--lod") {
                std::stringstream list(value());
                for (std::string item; std::getline(list, item, ',');) lods.push_back(item);
            } else if (arg == "--axis-only")
                axisOnly = true;
            else if (arg == "--elevation")
                elevation = std::stod(value());
            else if (arg == "--pixel-filter")
                pixelFilter = std::stod(value());
            else if (arg == "--ewa")
                ewa = true;
            else if (arg == "--truth")
                truth = value();
            else if (arg == "-h" || arg == "--help") {
                usage();
                return 0;
            } else if (!arg.empty() && arg[0] == '-') {
                usage();
                return 2;
            } else
                positional.push_back(arg);
        }
        if (positional.size() > 2) {
            usage();
            return 2;
        }
        if (positional.size() > 0) volumeSpec = positional[0];
        if (positional.size() > 1) tf = positional[1];
        if (size < 1) throw std::runtime_error("--size must be >= 1");
        if (supersample < 1 || supersample > 16)
            throw std::runtime_error("--supersample must be between 1 and 16");
        if (!(pixelFilter >= 0 && pixelFilter <= 4))
            throw std::runtime_error("--pixel-filter must be between 0 and 4 pixels");
        const Truth judge = parseTruth(truth);

        const Volume volume = loadVolume(volumeSpec);
        const VolumeStats vs = volumeStats(volume);
        RenderSettings base;
        base.mode = parseMode(mode);
        if (classify != "pre" && classify != "post")
            throw std::runtime_error("--classify must be pre or post");
        base.classification = classify == "post" ? Classification::Post : Classification::Pre;
        base.transfer = TransferFunction::load(tf).resolved(vs.minValue, vs.maxValue);
        base.camera.width = base.camera.height = size;
        base.camera.elevationDeg = elevation;
        if (earlyTermination >= 0) base.quality.earlyTermination = earlyTermination;
        base.quality.pixelFilter = pixelFilter;
        // Pixels per voxel (its largest spacing over the pixel size): below 1, the
        // point-sampled reference is aliased and the filtered one is the truth (auto).
        const double voxel =
            std::max(volume.spacing.x, std::max(volume.spacing.y, volume.spacing.z));
        const double voxelPixels = voxel / Camera(base.camera, volume).pixelSize;
        const bool withFiltered = judge == Truth::Filtered ||
                                  (judge == Truth::Auto && (pixelFilter > 0 || voxelPixels < 1));
        const double filterSigma = pixelFilter > 0 ? pixelFilter : Quality::kEwaDefaultSigma;

        std::vector<Config> configs = {{"axis", RendererKind::Axis, 1.0},
                                       {"sheet, slab 1", RendererKind::Sheet, 1.0},
                                       {"sheet, slab 0.5", RendererKind::Sheet, 0.5},
                                       {"sheet, slab 0.25", RendererKind::Sheet, 0.25}};
        if (ewa) {
            configs.insert(configs.begin() + 1,
                           {{"axis, EWA off", RendererKind::Axis, 1.0, 0, Ewa::Off},
                            {"axis, EWA on", RendererKind::Axis, 1.0, 0, Ewa::On}});
            configs.insert(configs.begin() + 4,
                           {{"sheet, slab 1, EWA off", RendererKind::Sheet, 1.0, 0, Ewa::Off},
                            {"sheet, slab 1, EWA on", RendererKind::Sheet, 1.0, 0, Ewa::On}});
        }
        std::size_t at = ewa ? 2 : 1;  // after "axis" (and "axis, EWA")
        for (const std::string& l : lods) {
            // "brick": per-brick levels (Quality::lodBrick), marked by lod -1 here.
            const bool lodAuto = l == "auto";
            const double lod = lodAuto ? 0 : (l == "brick" ? -1.0 : std::stod(l));
            if (!lodAuto && !(lod > 0) && lod != -1.0) continue;
            std::vector<Config> add = {
                {"axis, lod " + l, RendererKind::Axis, 1.0, lod, Ewa::Off, lodAuto}};
            if (ewa)
                add.push_back(
                    {"axis, lod " + l + ", EWA", RendererKind::Axis, 1.0, lod, Ewa::On, lodAuto});
            add.push_back(
                {"sheet, slab 1, lod " + l, RendererKind::Sheet, 1.0, lod, Ewa::Off, lodAuto});
            if (ewa)
                add.push_back({"sheet, slab 1, lod " + l + ", EWA", RendererKind::Sheet, 1.0, lod,
                               Ewa::On, lodAuto});
            configs.insert(configs.begin() + std::ptrdiff_t(at), add.begin(), add.end());
            at += add.size();
        }
        if (axisOnly)
            std::erase_if(configs, [](const Config& c) { return c.kind != RendererKind::Axis; });
        std::printf(
            "Accuracy against the reference ray caster: %s, %dx%d, %s %s, transfer "
            "function %s, default kernel and reference settings (step %g voxels, "
            "tolerance %g, %d x %d rays per pixel box-filtered), splatter early termination "
            "%g; %.3g pixels per voxel.\n\n",
            volumeSpec.c_str(), size, size, mode.c_str(), classify.c_str(), tf.c_str(),
            base.quality.referenceStep, base.quality.referenceTolerance, supersample, supersample,
            base.quality.earlyTermination, voxelPixels);
        if (withFiltered) {
            std::printf(
                "Columns 'point': against the point-sampled reference (one ray per pixel "
                "centre); 'filtered': against the reference through a Gaussian pixel filter of "
                "sigma %g pixels (tolerance %g)%s.\n\n",
                filterSigma, base.quality.pixelFilterTolerance,
                voxelPixels < 1 ? ", the truth where a voxel covers less than a pixel" : "");
            std::printf(
                "| azimuth | renderer | RMSE point | RMSE filtered | PSNR filtered (dB) | max abs "
                "filtered | ms/frame |\n");
            std::printf("|---:|---|---:|---:|---:|---:|---:|\n");
        } else {
            std::printf("| azimuth | renderer | RMSE | PSNR (dB) | max abs | ms/frame |\n");
            std::printf("|---:|---|---:|---:|---:|---:|\n");
        }
        for (double az : azimuths) {
            RenderSettings rs = base;
            rs.renderer = RendererKind::Reference;
            rs.camera.azimuthDeg = az;
            rs.quality.pixelFilter = 0;
            RenderStats refStats;
            const int n = supersample;
            if (n > 1) {  // N x N rays per pixel: the same view at N times the size
                rs.camera.pixelSize = Camera(rs.camera, volume).pixelSize / n;
                rs.camera.width = rs.camera.height = size * n;
            }
            const Renderer reference(volume, rs);
            const auto t0 = std::chrono::steady_clock::now();
            const Image fine = reference.render(&refStats);
            Image ref(size, size);
            for (int y = 0; y < size; ++y)
                for (int x = 0; x < size; ++x) {
                    glm::vec4 sum(0.0f);
                    for (int b = 0; b < n; ++b)
                        for (int a = 0; a < n; ++a) sum += fine.at(x * n + a, y * n + b);
                    ref.at(x, y) = sum / float(n * n);
                }
            const double refMs =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                    .count();
            Image filtered;
            if (withFiltered) {
                RenderSettings fs = base;
                fs.renderer = RendererKind::Reference;
                fs.camera.azimuthDeg = az;
                fs.quality.pixelFilter = filterSigma;
                RenderStats fst;
                const auto f0 = std::chrono::steady_clock::now();
                filtered = Renderer(volume, fs).render(&fst);
                const double fMs = std::chrono::duration<double, std::milli>(
                                       std::chrono::steady_clock::now() - f0)
                                       .count();
                std::printf("| %g | reference (final step %g) | – | – | – | – | %.0f |\n", az,
                            refStats.referenceStep, refMs);
                const ImageMetrics fm = compareImages(ref, filtered);
                std::printf(
                    "| %g | filtered reference (%d x %d rays per pixel, last change %.2g) | – | "
                    "%.3g | %.1f | %.3g | %.0f |\n",
                    az, fst.pixelSamples, fst.pixelSamples, fst.pixelFilterChange, fm.rmse,
                    fm.psnr, fm.maxAbs, fMs);
            } else
                std::printf("| %g | reference (final step %g) | – | – | – | %.0f |\n", az,
                            refStats.referenceStep, refMs);
            std::fflush(stdout);
            for (const Config& c : configs) {
                RenderSettings s = base;
                s.renderer = c.kind;
                s.quality.slab = c.slab;
                s.quality.lod = c.lodAuto       ? LevelOfDetail::automatic()
                                : c.lod == -1.0 ? LevelOfDetail::perBrick()
                                                : LevelOfDetail::threshold(c.lod);
                s.quality.ewa = c.ewa;
                s.camera.azimuthDeg = az;
                const Renderer renderer(volume, s);
                renderer.render();  // warm-up (first-touch allocations, the level of detail)
                RenderStats st;
                const auto a = std::chrono::steady_clock::now();
                const Image im = renderer.render(&st);
                const double ms =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a)
                        .count();
                const ImageMetrics m = compareImages(im, ref);
                const std::string label =
                    c.label + (c.ewa == Ewa::Auto && st.ewaSigma > 0 ? ", EWA" : "") +
                    (st.lodLevel ? " (level " + std::to_string(st.lodLevel) + ", " +
                                       std::to_string(st.lodSplats) + " splats" +
                                       perLevel(st.lodLevelSplats) + ")"
                                 : "");
                if (withFiltered) {
                    const ImageMetrics f = compareImages(im, filtered);
                    std::printf("| %g | %s | %.3g | %.3g | %.1f | %.3g | %.1f |\n", az,
                                label.c_str(), m.rmse, f.rmse, f.psnr, f.maxAbs, ms);
                } else
                    std::printf("| %g | %s | %.3g | %.1f | %.3g | %.1f |\n", az, label.c_str(),
                                m.rmse, m.psnr, m.maxAbs, ms);
                std::fflush(stdout);
            }
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_accuracy: error: %s\n", e.what());
        return 1;
    }
}
