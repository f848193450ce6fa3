// `splat render` in bricks (bricked_render.h).
#include "bricked_render.h"

#include <cstdio>
#include <filesystem>

#include "diagnostics.h"
#include "parallel.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/bricks.h"
#include "splat/error.h"
#include "splat/image_io.h"

namespace splat::cli {

void renderBrickedToFile(const VolumeArgs& volume, const RenderArgs& render,
                         RenderSettings settings, int bricks, const std::string& output,
                         BrickComposite composite) {
    const LoadOptions options = loadOptionsFromArgs(volume);
    bool alone = false;
    Volume geometry = volumeGeometry(volume.spec, options, &alone);
    if (!volume.backgroundValue.empty() && volume.backgroundValue != "auto") {
        geometry.background = std::stof(volume.backgroundValue);
        geometry.backgroundSource = "--background-value";
    } else if (alone && volume.spec.rfind("synthetic:", 0) != 0) {
        throw Error(volume.spec +
                    ": --bricks reads only each brick, and the background value is the median "
                    "of the whole volume's outer faces: give it with --background-value");
    }
    if (!alone)
        warn(volume.spec +
             ": its samples are not read by byte ranges (compressed, or not a .raw file): every "
             "rank loads the whole volume once and keeps its brick");
    if (settings.renderer == RendererKind::Sheet && composite == BrickComposite::Fast)
        warn(
            "--renderer sheet with --brick-composite fast is approximate where its slabs cross a "
            "brick face (README \"Beyond one machine\"); --brick-composite exact is not");
    char b[64];
    std::snprintf(b, sizeof b, "%.9g", double(geometry.background));
    runMetadata().push_back(
        {"splat:background_value", std::string(b) + " (" + geometry.backgroundSource + ")"});
    settings = withFreeCameraTarget(settings, geometry);
    const std::unique_ptr<BrickGroup> group = brickGroup();
    if (bricks > int(std::min<std::size_t>(geometry.voxelCount(), 1 << 20)))
        throw UsageError("--bricks " + std::to_string(bricks) + " is more than the volume's " +
                         std::to_string(geometry.voxelCount()) + " samples");
    BrickStats st;
    const Image image = renderBricked(
        geometry,
        [&](const Brick& brick) {
            return loadVolumeBrick(volume.spec, options, brick.loadLo, brick.loadHi);
        },
        settings, bricks, *group, &st, composite);
    const std::vector<BrickStats> all = group->gather(st);
    if (workerProcess()) return;
    removeStaleTemporaries(std::filesystem::path(output).parent_path());
    writeImage(output, image, displayOptions(render, settings, image));
    std::printf(
        "wrote %s: %dx%d, %s %s, %d bricks (ghost layers as wide as the kernel) on %d "
        "processes, composite %.1f ms\n",
        output.c_str(), image.width, image.height, toString(settings.renderer),
        toString(settings.mode), st.bricks, group->size(), st.compositeMs);
    for (std::size_t r = 0; r < all.size(); ++r)
        std::printf(
            "rank %zu: %d bricks, largest %zu samples (%.1f MiB), %zu splats, load %.1f ms, "
            "scene %.1f ms, render %.1f ms, exchanged %llu bytes\n",
            r, all[r].rendered, all[r].samplesLoaded, all[r].samplesLoaded * 4.0 / 1048576.0,
            all[r].splats, all[r].loadMs, all[r].sceneMs, all[r].renderMs,
            static_cast<unsigned long long>(all[r].bytesExchanged));
}

}  // namespace splat::cli
