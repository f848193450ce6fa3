// `splat render VOLUME [options] -o OUT.(png|exr|tif)`: one frame.
#include <cstdio>
#include <memory>

#include "bricked_render.h"
#include "commands.h"
#include "diagnostics.h"
#include "gaussian_scenes.h"
#include "parallel.h"
#include "render_options.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/gaussians.h"
#include "splat/image_io.h"
#include "volume_options.h"

namespace splat::cli {

namespace {

/// The --lod value as the level-of-detail lines print it.
std::string lodText(const LevelOfDetail& lod) {
    switch (lod.kind) {
        case LevelOfDetail::Kind::Auto:
            return "auto";
        case LevelOfDetail::Kind::Brick:
            return "brick";
        default:
            return std::to_string(lod.pixels);
    }
}

struct RenderCommand {
    VolumeArgs volume;
    RenderArgs render;
    std::string output;
    int bricks = 0;
    std::string brickComposite = "exact";
    std::string compositor = "direct";
    double rankMemory = 0;  ///< MiB; 0: the default under mpirun, off otherwise
};
}  // namespace

void registerRender(CLI::App& app) {
    auto args = std::make_shared<RenderCommand>();
    CLI::App* cmd = app.add_subcommand("render", "render one image of a volume");
    addVolumeOptions(*cmd, args->volume);
    addRenderOptions(*cmd, args->render, true);
    constexpr unsigned R = kRenderCommandOptions;
    addTableOption(*cmd, "output", args->output, R);
    addTableOption(*cmd, "bricks", args->bricks, R);
    addTableOption(*cmd, "rank-memory", args->rankMemory, R);
    addTableOption(*cmd, "brick-composite", args->brickComposite, R);
    addTableOption(*cmd, "compositor", args->compositor, R);
    cmd->footer(
        "Examples:\n"
        "  splat render ch2.nii.gz --tf mri-head --azimuth 30 -o head.png\n"
        "  splat render synthetic:phantom:64 --renderer sheet --slab 0.5 --mode mip -o p.exr\n"
        "  splat render --scene view.json --size 1024x1024 -o big.png   (flags override the "
        "scene)");
    cmd->callback([args, cmd] {
        prepareCommand(*cmd, {"volume", "output"});
        checkImageOutput(args->output);
        if (isGaussianScene(args->volume.spec)) {
            beginRun(*cmd);
            renderGaussianFile(*cmd, args->render, args->volume.spec, args->output);
            finishRun(*cmd);
            return;
        }
        RenderUse use;
        use.imageExt = lowerExtension(args->output);
        RenderSettings settings = settingsFromArgs(args->render, use);
        loadOptionsFromArgs(args->volume);  // malformed volume options: usage errors, now
        chooseZarrLevel(args->volume, settings);
        if (args->bricks < 0 || args->bricks > 4096)
            throw UsageError("--bricks must be between 0 and 4096");
        if (args->brickComposite != "exact" && args->brickComposite != "fast")
            throw UsageError("--brick-composite must be exact or fast (got '" +
                             args->brickComposite + "')");
        if (!(args->rankMemory >= 0 && args->rankMemory <= 1e9))
            throw UsageError("--rank-memory must be between 0 and 1e9 MiB");
        checkCompositor(args->compositor);
        if (given(*cmd, "compositor") && !fromScene(*cmd, "compositor") && processCount() == 1)
            warn("--compositor applies to bricks under mpirun: ignored");
        bool bricked = args->bricks > 0 || args->rankMemory > 0 || processCount() > 1;
        int bricks = args->bricks;
        if (!bricked) {  // docs/parallel.md "Larger than memory"
            bricks = automaticBricks(args->volume, settings);
            bricked = bricks > 0;
        }
        if (given(*cmd, "brick-composite") && !fromScene(*cmd, "brick-composite") &&
            (!bricked || settings.renderer != RendererKind::Sheet))
            warn(
                "--brick-composite applies to bricked renders (--bricks or mpirun) of "
                "--renderer sheet: ignored");
        // docs/parallel.md: bricks when asked, or chosen from the budget.
        if (bricked) {
            if (!workerProcess()) beginRun(*cmd);
            renderBrickedToFile(
                args->volume, args->render, settings, bricks,
                std::uint64_t(args->rankMemory * 1048576.0), args->output,
                args->brickComposite == "exact" ? BrickComposite::Exact : BrickComposite::Fast,
                args->compositor);
            if (!workerProcess()) finishRun(*cmd);
            return;
        }
        beginRun(*cmd);
        const Volume volume = loadVolumeFromArgs(args->volume);
        settings = withDataDefaults(args->render, settings, volume);
        const Renderer renderer(volume, settings);
        RenderStats stats;
        const Image image = renderer.render(&stats);
        removeStaleTemporaries(std::filesystem::path(args->output).parent_path());
        writeImage(args->output, image, displayOptions(args->render, settings, image));
        const double skipped =
            stats.voxels ? 100.0 * (1.0 - double(stats.splats) / stats.voxels) : 0.0;
        std::printf(
            "wrote %s: %dx%d, %s %s, %zu splats of %zu voxels (%.1f%% skipped, splat list "
            "%.1f MiB), %.1f ms\n",
            args->output.c_str(), image.width, image.height, toString(settings.renderer),
            toString(settings.mode), stats.splats, stats.voxels, skipped,
            renderer.splats().bytes() / 1048576.0, stats.milliseconds);
        // What the frame modelled.
        std::printf(
            "modelled: %zu voxels classified away, gradients %s, %s path%s, %zu splats "
            "early-terminated, %zu footprint pixels\n",
            stats.voxels - stats.splats, stats.normals ? "computed" : "not computed",
            stats.perspective ? "perspective" : "orthographic",
            stats.exactPixels ? " (eye near the volume: exact path for every pixel)" : "",
            stats.culledSplats, stats.footprintPixels);
        if (stats.exactPixels > 0)
            warn(std::to_string(stats.exactPixels) + " of " +
                 std::to_string(std::size_t(image.width) * std::size_t(image.height)) +
                 " pixels handed to the exact path: " + stats.exactReason);
        // A frame of `--lod auto` may mix levels, one per brick: the splats of each.
        std::string perLevel;
        int levelsUsed = 0;
        for (std::size_t l = 0; l < stats.lodLevelSplats.size(); ++l)
            if (stats.lodLevelSplats[l] > 0) {
                perLevel += (perLevel.empty() ? "" : ", ") + std::string("level ") +
                            std::to_string(l) + " " + std::to_string(stats.lodLevelSplats[l]);
                ++levelsUsed;
            }
        if (stats.lodLevel > 0 && levelsUsed > 1)
            std::printf("level of detail %d: %zu splats, a level per brick (%s) (--lod %s)\n",
                        stats.lodLevel, stats.lodSplats, perLevel.c_str(),
                        lodText(settings.quality.lod).c_str());
        else if (stats.lodLevel > 0)
            std::printf("level of detail %d: %zu splats of %dx%dx%d voxels each (--lod %s)\n",
                        stats.lodLevel, stats.lodSplats, 1 << stats.lodLevel, 1 << stats.lodLevel,
                        1 << stats.lodLevel, lodText(settings.quality.lod).c_str());
        finishRun(*cmd);
    });
}

}  // namespace splat::cli
