// `splat render` in bricks (bricked_render.h).
#include "bricked_render.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "diagnostics.h"
#include "footprint/kernel.h"
#include "parallel.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/brick_budget.h"
#include "splat/bricks.h"
#include "splat/error.h"
#include "splat/image_io.h"

namespace splat::cli {

int bricksFromBudget(const Volume& geometry, const RenderSettings& settings, int ranks,
                     std::uint64_t rankBytes, bool* wholeFits, bool quiet,
                     double extraSampleBytes) {
    const footprint::Kernel kernel =
        footprint::Kernel::fromName(settings.kernel, settings.kernelSigma, settings.kernelRadius);
    BrickBudget budget;
    budget.rankBytes = rankBytes ? rankBytes : defaultRankBytes(ranks);
    budget.ranks = ranks;
    budget.width = settings.camera.width;
    budget.height = settings.camera.height;
    budget.ghost = ghostLayers(kernel.radius(), geometry.spacing);
    budget.extraSampleBytes = extraSampleBytes;
    const BrickChoice c = chooseBricks(geometry.dims, budget);
    if (wholeFits) *wholeFits = c.wholeFits;
    if (!workerProcess() && !quiet) {
        const double mib = 1048576.0;
        std::printf(
            "bricks: %d (%d per process) for a budget of %.1f MiB per process%s: estimated "
            "%.1f MiB for the busiest (largest brick %llu samples); the whole volume %s\n",
            c.bricks, (c.bricks + ranks - 1) / ranks, double(budget.rankBytes) / mib,
            rankBytes ? " (--rank-memory)" : " (80% of physical memory / processes on the node)",
            double(c.rankBytes) / mib, static_cast<unsigned long long>(c.largestBrick),
            c.wholeFits ? "fits one process" : "does not fit one process");
        if (!c.withinBudget && !c.wholeFits)
            warn("even " + std::to_string(c.bricks) +
                 " bricks exceed the budget per process by the estimate; rendering anyway");
    }
    return c.bricks;
}

void addSequenceBrickOptions(CLI::App& cmd, SequenceBrickArgs& b, unsigned sets) {
    addTableOption(cmd, "bricks", b.bricks, sets);
    addTableOption(cmd, "rank-memory", b.rankMemory, sets);
    addTableOption(cmd, "brick-composite", b.composite, sets);
    addTableOption(cmd, "compositor", b.compositor, sets);
}

void checkSequenceBrickOptions(const CLI::App& cmd, const SequenceBrickArgs& b) {
    if (b.bricks < 0 || b.bricks > 4096) throw UsageError("--bricks must be between 0 and 4096");
    if (!(b.rankMemory >= 0 && b.rankMemory <= 1e9))
        throw UsageError("--rank-memory must be between 0 and 1e9 MiB");
    if (b.composite != "exact" && b.composite != "fast")
        throw UsageError("--brick-composite must be exact or fast (got '" + b.composite + "')");
    checkCompositor(b.compositor);
    if (given(cmd, "compositor") && !fromScene(cmd, "compositor") && processCount() == 1)
        warn("--compositor applies to bricks under mpirun: ignored");
}

SequenceBricks chooseSequenceBricks(const VolumeArgs& volume, RenderSettings& settings, int bricks,
                                    double rankMiB, double extraSampleBytes) {
    SequenceBricks c;
    c.bricks = bricks;
    const std::uint64_t rankBytes = std::uint64_t(rankMiB * 1048576.0);
    if (bricks == 0 && rankBytes == 0 && processCount() == 1) return c;
    c.geometry = brickedGeometry(volume, &c.alone);
    settings = withFreeCameraTarget(settings, *c.geometry);
    if (c.bricks == 0) {
        bool fits = true;
        bricksFromBudget(*c.geometry, settings, processCount(), rankBytes, &fits, true,
                         extraSampleBytes);
        if (!fits)
            c.bricks = bricksFromBudget(*c.geometry, settings, processCount(), rankBytes, nullptr,
                                        false, extraSampleBytes);
    }
    if (c.bricks > int(std::min<std::size_t>(c.geometry->voxelCount(), 1 << 20)))
        throw UsageError("--bricks " + std::to_string(c.bricks) + " is more than the volume's " +
                         std::to_string(c.geometry->voxelCount()) + " samples");
    return c;
}

double poppingSampleBytes(const std::vector<RendererKind>& renderers, double splatShare) {
    double bytes = 0;
    for (std::size_t k = 1; k < renderers.size(); ++k) bytes += splatShare * 26.0;
    for (RendererKind r : renderers) {
        if (r == RendererKind::Reference) bytes += 20.0;
        if (r == RendererKind::Sheet) bytes += splatShare * 50.0;
    }
    return bytes;
}

std::function<Volume(const Brick&)> brickLoader(const VolumeArgs& volume) {
    const LoadOptions options = loadOptionsFromArgs(volume);
    return [spec = volume.spec, options](const Brick& brick) {
        return loadVolumeBrick(spec, options, brick.loadLo, brick.loadHi);
    };
}

Volume brickedGeometry(const VolumeArgs& volume, bool* aloneOut) {
    const LoadOptions options = loadOptionsFromArgs(volume);
    const std::string& background = volume.values.text("background-value");
    const bool given = !background.empty() && background != "auto";
    bool alone = false;
    Volume geometry = volumeGeometry(volume.spec, options, &alone, !given);
    if (given) {
        geometry.background = std::stof(background);
        geometry.backgroundSource = "--background-value";
    }
    if (aloneOut)
        *aloneOut = alone;
    else if (!alone)
        warn(volume.spec +
             ": its samples are not read by brick (DICOM, a slice folder, NRRD text or hex, an "
             "ANALYZE pair): every rank loads the whole volume once and keeps its brick");
    return geometry;
}

void renderBrickedToFile(const VolumeArgs& volume, const RenderArgs& render,
                         RenderSettings settings, int bricks, std::uint64_t rankBytes,
                         const std::string& output, BrickComposite composite,
                         const std::string& compositor) {
    const Volume geometry = brickedGeometry(volume);
    if (settings.renderer == RendererKind::Sheet && composite == BrickComposite::Fast)
        warn(
            "--renderer sheet with --brick-composite fast is approximate where its slabs cross a "
            "brick face (docs/parallel.md); --brick-composite exact is not");
    char b[64];
    std::snprintf(b, sizeof b, "%.9g", double(geometry.background));
    runMetadata().push_back(
        {"splat:background_value", std::string(b) + " (" + geometry.backgroundSource + ")"});
    settings = withFreeCameraTarget(settings, geometry);
    const std::unique_ptr<BrickGroup> group = brickGroup(compositor);
    if (bricks == 0) bricks = bricksFromBudget(geometry, settings, group->size(), rankBytes);
    if (bricks > int(std::min<std::size_t>(geometry.voxelCount(), 1 << 20)))
        throw UsageError("--bricks " + std::to_string(bricks) + " is more than the volume's " +
                         std::to_string(geometry.voxelCount()) + " samples");
    BrickStats st;
    const Image image =
        renderBricked(geometry, brickLoader(volume), settings, bricks, *group, &st, composite);
    const std::vector<BrickStats> all = group->gather(st);
    if (workerProcess()) return;
    removeStaleTemporaries(std::filesystem::path(output).parent_path());
    writeImage(output, image, displayOptions(render, settings, image));
    std::printf(
        "wrote %s: %dx%d, %s %s, %d bricks (ghost layers as wide as the kernel) on %d "
        "processes, composite %.1f ms\n",
        output.c_str(), image.width, image.height, toString(settings.renderer),
        toString(settings.mode), st.bricks, group->size(), st.compositeMs);
    {
        // splat/brick_budget.h's estimate for the busiest process, beside its peak RSS.
        std::size_t largest = 0;
        int held = 0;
        for (const BrickStats& r : all) {
            largest = std::max(largest, r.samplesLoaded);
            held = std::max(held, r.rendered);
        }
        std::printf(
            "memory estimate: %.0f MiB for the busiest process (%zu samples, %d images)\n",
            double(brickMemoryEstimate(largest, image.width, image.height, held, 0.25)) / 1048576.0,
            largest, held);
    }
    for (std::size_t r = 0; r < all.size(); ++r)
        std::printf(
            "rank %zu: %d bricks, largest %zu samples (%.1f MiB), %zu splats, load %.1f ms, "
            "scene %.1f ms, render %.1f ms, exchanged %llu bytes\n",
            r, all[r].rendered, all[r].samplesLoaded, all[r].samplesLoaded * 4.0 / 1048576.0,
            all[r].splats, all[r].loadMs, all[r].sceneMs, all[r].renderMs,
            static_cast<unsigned long long>(all[r].bytesExchanged));
}

void printRankStats(const std::vector<BrickStats>& ranks, std::size_t frames, const char* scene) {
    for (std::size_t r = 0; r < ranks.size(); ++r)
        std::printf(
            "rank %zu: %d of %d bricks, largest %zu samples (%.1f MiB), load %.1f ms, scene %.1f "
            "ms%s; render %.1f ms, composite %.1f ms, exchanged %llu bytes over %zu frames\n",
            r, ranks[r].rendered, ranks[r].bricks, ranks[r].samplesLoaded,
            ranks[r].samplesLoaded * 4.0 / 1048576.0, ranks[r].loadMs, ranks[r].sceneMs, scene,
            ranks[r].renderMs, ranks[r].compositeMs,
            static_cast<unsigned long long>(ranks[r].bytesExchanged), frames);
}

}  // namespace splat::cli
