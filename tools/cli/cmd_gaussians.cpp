// Gaussian scenes on the command line (gaussian_scenes.h).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>

#include "diagnostics.h"
#include "gaussian_scenes.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/gaussians.h"
#include "splat/image_io.h"
#include "volume_options.h"

namespace splat::cli {

RenderSettings gaussianViewOf(const RenderArgs& a) {
    OptionValues values = a.values;
    // What the run set (flags, a scene's keys) is marked given, so that the quality preset
    // keeps it (--slab, --ref-tolerance).
    if (a.cmd) readGiven(*a.cmd, values);
    values.set("renderer", "axis");
    return asOptionUsage([&] { return parseRenderOptions(values); });
}

namespace {

/// Whether the run sets `key` itself: a flag, or a scene's value other than the default (a
/// written scene holds every option, at its default when the run left it unset).
bool setByRun(const CLI::App& cmd, const RenderArgs& args, const std::string& key) {
    return given(cmd, key) && (!fromScene(cmd, key) || args.values.differsFromDefault(key));
}

}  // namespace

GaussianRenderOptions gaussianRenderOptions(const CLI::App& cmd, const RenderArgs& args,
                                            const RenderSettings& view) {
    GaussianRenderOptions o;
    o.threads = view.threads;
    o.slab = setByRun(cmd, args, "slab") ? view.quality.slab : 0;
    o.tolerance = view.quality.referenceTolerance;
    return o;
}

void printGaussianInfo(const std::string& spec) {
    const GaussianScene s = openGaussians(spec);
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    float oMin = INFINITY, oMax = -INFINITY, sMin = INFINITY, sMax = -INFINITY;
    for (std::size_t i = 0; i < s.size(); ++i) {
        lo = glm::min(lo, glm::dvec3(s.means[i]));
        hi = glm::max(hi, glm::dvec3(s.means[i]));
        oMin = std::min(oMin, s.opacities[i]);
        oMax = std::max(oMax, s.opacities[i]);
        const glm::vec3 sc = s.scales[i];
        sMin = std::min({sMin, sc.x, sc.y, sc.z});
        sMax = std::max({sMax, sc.x, sc.y, sc.z});
    }
    std::printf("%s: %s\n", spec.c_str(), s.source.c_str());
    std::printf("Gaussians: %zu, SH degree %d (%d coefficients per channel), %.1f MiB\n", s.size(),
                s.shDegree, s.shCount(), double(s.size()) * (11 + 3 * s.shCount()) * 4 / 1048576.0);
    std::printf("means:     x %g .. %g, y %g .. %g, z %g .. %g\n", lo.x, hi.x, lo.y, hi.y, lo.z,
                hi.z);
    std::printf("opacity:   %g .. %g\n", oMin, oMax);
    std::printf("scale:     %g .. %g (standard deviations, world units)\n", sMin, sMax);
}

void renderGaussianFile(const CLI::App& cmd, const RenderArgs& args, const std::string& spec,
                        const std::string& output) {
    const RenderSettings view = gaussianViewOf(args);
    GaussianRenderOptions o = gaussianRenderOptions(cmd, args, view);
    o.renderer = asUsage([&] {
        return parseGaussianRenderer(setByRun(cmd, args, "renderer") ? args.values.text("renderer")
                                                                     : "3dgs");
    });
    CameraParams camera = view.camera;
    const GaussianScene scene = openGaussians(spec);
    if (camera.lookAtSet && std::isnan(camera.lookAt.x)) camera.lookAt = scene.geometry().center();
    const auto t0 = std::chrono::steady_clock::now();
    const Image image = renderGaussians(scene, camera, o);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    WriteOptions w;
    writeImage(output, image, withMetadata(w));
    std::printf("wrote %s: %dx%d, %s, %zu Gaussians, %.1f ms\n", output.c_str(), image.width,
                image.height, gaussianRendererName(o.renderer), scene.size(), ms);
}

void registerGaussians(CLI::App& app) {
    struct Args {
        VolumeArgs volume;
        RenderArgs render;
        std::string output;
    };
    auto args = std::make_shared<Args>();
    CLI::App* cmd = app.add_subcommand(
        "gaussians", "write a volume's splats as a 3D Gaussian Splatting scene (.ply)");
    addVolumeOptions(*cmd, args->volume);
    addRenderOptions(*cmd, args->render, false);
    addOption(*cmd, "-o,--output", args->output, "output scene: .ply (3DGS binary)", "Output",
              PathKind::Output);
    cmd->footer(
        "One Gaussian per pre-classified splat (--tf, --kernel gaussian, --sigma): scales sigma "
        "x spacing, colour e / rho, opacity of the footprint at its centre.\n"
        "Examples:\n"
        "  splat gaussians ch2.nii.gz --tf mri-head -o ch2.ply\n"
        "  splat gaussians synthetic:blob:32 -o blob.ply");
    cmd->callback([args, cmd] {
        prepareCommand(*cmd, {"volume", "output"});
        if (!isGaussianScene(args->output) || args->output.rfind("gaussians:", 0) == 0)
            throw UsageError("the output of splat gaussians must be a .ply file");
        RenderUse use;
        RenderSettings settings = settingsFromArgs(args->render, use);
        const Volume volume = loadVolumeFromArgs(args->volume);
        settings = withDataDefaults(args->render, settings, volume);
        const GaussianScene scene = gaussiansFromVolume(volume, settings);
        if (scene.size() == 0) throw Error("the transfer function leaves no visible splat");
        writeGaussians(scene, args->output);
        std::printf("wrote %s: %zu Gaussians (sigma %g voxels)\n", args->output.c_str(),
                    scene.size(), scene.scales[0].x / volume.spacing.x);
    });
}

}  // namespace splat::cli
