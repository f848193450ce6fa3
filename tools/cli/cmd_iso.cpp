// `splat iso VOLUME --level L -o surface.ply|.obj|.stl`: the iso surface of the reconstructed
// field (background value included) as a mesh (splat/surface.h).
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "diagnostics.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/surface.h"
#include "volume_options.h"

namespace splat::cli {

namespace {
struct IsoCommand {
    VolumeArgs volume;
    double level = std::nan("");
    std::string output, kernel = "gaussian";
    double sigma = 0, radius = 0;
    int threads = 0;
};
}  // namespace

void registerIso(CLI::App& app) {
    auto a = std::make_shared<IsoCommand>();
    CLI::App* cmd = app.add_subcommand(
        "iso", "iso surface of the reconstructed field as a mesh (.ply, .obj, .stl)");
    addVolumeOptions(*cmd, a->volume);
    addTableOption(*cmd, "level", a->level, kIsoOptions)->required();
    addTableOption(*cmd, "kernel", a->kernel, kIsoOptions);
    addTableOption(*cmd, "sigma", a->sigma, kIsoOptions);
    addTableOption(*cmd, "radius", a->radius, kIsoOptions);
    addTableOption(*cmd, "threads", a->threads, kIsoOptions);
    addTableOption(*cmd, "output", a->output, kIsoOptions)->required();
    cmd->footer(
        "Examples:\n"
        "  splat iso synthetic:ct-phantom --level -500 -o skin.ply\n"
        "  splat iso ch2.nii.gz --level 60 -o brain.stl");
    cmd->callback([a, cmd] {
        prepareCommand(*cmd, {"volume", "output"});
        asUsage([&] {
            if (!std::isfinite(a->level)) throw Error("--level must be a finite number");
            const std::string ext = lowerExtension(a->output);
            if (ext != ".ply" && ext != ".obj" && ext != ".stl")
                throw Error(a->output + ": unknown mesh format '" + ext +
                            "' (expected .ply, .obj or .stl)");
            if (a->threads < 0 || a->threads > 4096) throw Error("--threads must be 0..4096");
            if (!(a->sigma >= 0 && a->sigma <= 1e3) || !(a->radius >= 0 && a->radius <= 1e3))
                throw Error("--sigma and --radius must be between 0 and 1000 voxels");
            return 0;
        });
        loadOptionsFromArgs(a->volume);
        beginRun(*cmd);
        const Volume volume = loadVolumeFromArgs(a->volume);
        const VolumeStats st = volumeStats(volume, 1);
        const double lo = std::min<double>(st.minValue, volume.background),
                     hi = std::max<double>(st.maxValue, volume.background);
        if (!(a->level > lo && a->level < hi)) {
            char b[160];
            std::snprintf(b, sizeof b, "no surface at level %g: the field takes values in %g .. %g",
                          a->level, lo, hi);
            throw Error(b);
        }
        SurfaceOptions o;
        o.kernel = a->kernel;
        o.kernelSigma = a->sigma;
        o.kernelRadius = a->radius;
        o.threads = a->threads;
        const Mesh mesh = extractIsosurface(volume, a->level, o);
        if (mesh.triangles.empty())
            throw Error("no surface at level " + std::to_string(a->level) +
                        ": the reconstructed field does not cross it");
        writeMesh(a->output, mesh);
        std::printf("wrote %s: %zu vertices, %zu triangles, level %g (background %g), max "
                    "|f - level| at the vertices %.3g\n",
                    a->output.c_str(), mesh.vertices.size(), mesh.triangles.size(), a->level,
                    double(volume.background), mesh.maxResidual);
    });
}

}  // namespace splat::cli
