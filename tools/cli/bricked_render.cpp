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
    // Outside dvr every sample that differs from b becomes a splat (classify keeps them all),
    // so the estimate cannot assume the transfer function drops most of them.
    if (settings.mode != RenderMode::Dvr) budget.splatShare = 1.0;
    budget.oneImageHeld = ranks == 1 && settings.renderer != RendererKind::Sheet;
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

std::function<bool(const Brick&)> brickEmptiness(const VolumeArgs& volume) {
    const std::string& background = volume.values.text("background-value");
    if (!background.empty() && background != "auto") return {};  // b is not the file's
    const LoadOptions options = loadOptionsFromArgs(volume);
    return [spec = volume.spec, options](const Brick& brick) {
        return brickHoldsOnlyBackground(spec, options, brick.loadLo, brick.loadHi);
    };
}

namespace {

/// Whether a volume of b draws one constant image in `settings` (emptyBrickImage), the
/// transfer function and iso level resolved against the sparse volume's range: else every
/// brick of it draws, and bricks gain nothing over the whole volume.
bool backgroundDrawsOneImage(const VolumeArgs& volume, const LoadOptions& options,
                             const Volume& geometry, RenderSettings s) {
    if (!brickEmptiness(volume)) return false;
    float lo = 0, hi = 0;
    if (!sparseValueRange(volume.spec, options, lo, hi)) return false;
    s.transfer = s.transfer.resolved(lo, hi);
    if (s.isoNormalized) {
        s.isoLevel = lo + s.isoLevel * (hi - lo);
        s.isoNormalized = false;
    }
    s = withFreeCameraTarget(s, geometry);
    Brick whole;
    whole.hi = whole.loadHi = geometry.dims;
    return emptyBrickImage(geometry, brickSettings(s, geometry, whole, geometry.dims)).has_value();
}

}  // namespace

int automaticBricks(const VolumeArgs& volume, const RenderSettings& settings) {
    if (settings.edges.enabled() || settings.labels.enabled) return 0;
    // Post-classified dvr draws the transfer function's value at b wherever the field is b;
    // bricks draw that haze per brick, not as one volume.
    if (settings.mode == RenderMode::Dvr && settings.classification == Classification::Post)
        return 0;
    const Quality& q = settings.quality;
    if (q.lod.kind != LevelOfDetail::Kind::Off) return 0;
    if (settings.renderer == RendererKind::Sheet &&  // its exact bricks refuse these
        (settings.clipping.enabled() || settings.camera.projection == Projection::Perspective))
        return 0;
    const LoadOptions options = loadOptionsFromArgs(volume);
    Volume geometry;
    try {
        if (!volumeReadsByBrick(volume.spec, options)) return 0;
        bool alone = false;
        geometry = volumeGeometry(volume.spec, options, &alone, false);
    } catch (const std::exception&) {
        return 0;  // the whole volume's load says what is wrong, as without bricks
    }
    // Bricks make the samples per process smaller, never the images: a frame whose images
    // alone exceed the budget renders whole (and its own checks say what is wrong).
    if (brickMemoryEstimate(0, settings.camera.width, settings.camera.height, 1, 0.0) >
        defaultRankBytes(1))
        return 0;
    bool fits = true;
    const int needed = bricksFromBudget(geometry, settings, 1, 0, &fits, true);
    const std::size_t cap = std::min<std::size_t>(geometry.voxelCount(), 4096);
    if (volumeIsSparse(volume.spec) && backgroundDrawsOneImage(volume, options, geometry, settings)) {
        const std::size_t k = (geometry.voxelCount() + kSparseBrickSamples - 1) / kSparseBrickSamples;
        return int(std::clamp<std::size_t>(std::max<std::size_t>(k, std::size_t(fits ? 1 : needed)),
                                           1, cap));
    }
    if (fits) return 0;
    std::fprintf(stderr,
                 "splat: %s: %dx%dx%d samples do not fit the memory budget of %.0f MiB "
                 "(docs/parallel.md \"Larger than memory\"): rendering %d bricks one after "
                 "another\n",
                 volume.spec.c_str(), geometry.dims.x, geometry.dims.y, geometry.dims.z,
                 double(defaultRankBytes(1)) / 1048576.0, needed);
    return needed;
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
    settings = withDataDefaults(render, settings, geometry);  // as the whole volume's frame
    const std::unique_ptr<BrickGroup> group = brickGroup(compositor);
    if (bricks == 0) bricks = bricksFromBudget(geometry, settings, group->size(), rankBytes);
    if (bricks > int(std::min<std::size_t>(geometry.voxelCount(), 1 << 20)))
        throw UsageError("--bricks " + std::to_string(bricks) + " is more than the volume's " +
                         std::to_string(geometry.voxelCount()) + " samples");
    BrickStats st;
    const Image image = renderBricked(geometry, brickLoader(volume), settings, bricks, *group, &st,
                                      composite, brickEmptiness(volume));
    const std::vector<BrickStats> all = group->gather(st);
    if (workerProcess()) return;
    removeStaleTemporaries(std::filesystem::path(output).parent_path());
    writeImage(output, image, displayOptions(render, settings, image));
    std::printf(
        "wrote %s: %dx%d, %s %s, %d bricks (ghost layers as wide as the kernel) on %d "
        "processes, composite %.1f ms\n",
        output.c_str(), image.width, image.height, toString(settings.renderer),
        toString(settings.mode), st.bricks, group->size(), st.compositeMs);
    int empty = 0;
    for (const BrickStats& r : all) empty += r.empty;
    if (empty > 0)
        std::printf("bricks holding only the background value: %d of %d\n", empty, st.bricks);
    {
        // splat/brick_budget.h's estimate for the busiest process, beside its peak RSS.
        std::size_t largest = 0;
        int held = 0;
        for (const BrickStats& r : all) {
            largest = std::max(largest, r.samplesLoaded);
            held = std::max(held, r.rendered);
        }
        // One process composites each partial image as it is rendered: the frame and one.
        if (group->size() == 1) held = std::min(held, 2);
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
