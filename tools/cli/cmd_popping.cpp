// `splat popping VOLUME [render options] --from DEG --to DEG --step DEG [--sweep
// azimuth|elevation] [--renderers axis,sheet,reference] [--refine N] --report DIR`: renders
// a sweep with each renderer from one Scene, finds where the axis-aligned splatter pops and
// proves it is a discontinuity, and writes report.html, metrics.csv and summary.json.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>

#include "bricked_render.h"
#include "bricked_requests.h"
#include "commands.h"
#include "diagnostics.h"
#include "gaussian_scenes.h"
#include "parallel.h"
#include "popping_options.h"
#include "progress.h"
#include "render_options.h"
#include "resume_journal.h"
#include "scene_file.h"
#include "splat/error.h"
#include "splat/popping.h"
#include "volume_options.h"

namespace splat::cli {

namespace {

/// The predicted sheet switches (or order swaps): every one up to 20, else the first 10 and
/// the count.
void printPredicted(const PoppingResult& r, const char* unit) {
    const std::vector<double>& p = r.predictedSwitches;
    const std::string& what = r.options.predictedName;
    const std::size_t shown = p.size() <= 20 ? p.size() : 10;
    for (std::size_t i = 0; i < shown; ++i)
        std::printf("predicted %s at %.6f%s\n", what.c_str(), p[i], unit);
    if (shown < p.size())
        std::printf("... %zu predicted %s%s in all (summary.json lists them)\n", p.size(),
                    what.c_str(), what.back() == 'h' ? "es" : "s");
}

struct PoppingCommand {
    VolumeArgs volume;
    RenderArgs render;
    PoppingArgs popping;
    std::string report;
    SequenceBrickArgs brick;
    bool quiet = false, resume = false;
};

/// A temporal FLIP mean for the table: "-" when not measured (RendererSeries::flipWarp1Mean).
std::string warpedColumn(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4f", v);
    return v >= 0 ? buf : "-";
}

}  // namespace

void printPoppingSummary(const PoppingResult& r) {
    std::printf("%-10s %12s %12s %10s %8s %10s %10s %12s\n", "renderer", "spike ratio", "median T",
                "flicker", "events", "FLIP1 warp", "FLIP7 warp", "ms/frame");
    for (const RendererSeries& s : r.series) {
        int events = 0;
        for (const PoppingEvent& e : r.events) events += &r.series[e.series] == &s;
        std::printf("%-10s %12.2f %12.3g %10.2f %8d %10s %10s %12.1f\n", s.name.c_str(),
                    s.spikeRatio, s.medianT, s.flickerRatio, events,
                    warpedColumn(s.flipWarp1Mean).c_str(), warpedColumn(s.flipWarp7Mean).c_str(),
                    s.msPerFrame);
    }
    for (const RendererSeries& s : r.series) {
        std::size_t exact = 0;
        for (std::size_t p : s.exactPixels) exact += p > 0;
        if (exact > 0)
            warn(s.name + ": " + std::to_string(exact) + " of " +
                 std::to_string(s.exactPixels.size()) +
                 " views handed to the exact path (the reference's pixels): " + s.exactReason);
    }
    // Positions: degrees of a sweep, or view positions of a camera path.
    const char* unit = r.pathViews > 0 ? " (path position)" : " degrees";
    printPredicted(r, unit);
    for (const PoppingEvent& e : r.events) {
        const std::string axes = e.sheetAxisBefore < 0 && e.sheetAxisAfter < 0
                                     ? ""
                                     : "; sheet axis " + std::to_string(e.sheetAxisBefore) +
                                           " -> " + std::to_string(e.sheetAxisAfter);
        std::printf(
            "event (%s) %.4g..%.4g: signal %.3g; refined to %.3g%s at %.6f: jump "
            "%.3g, slope %.2f (%s)%s%s\n",
            r.series[e.series].name.c_str(), e.angleFrom, e.angleTo, e.signal, e.refinedWidth, unit,
            e.refinedAngle, e.refinedJump, e.refinedSlope,
            std::abs(e.refinedSlope) < 0.25 ? "a discontinuity" : "continuous change", axes.c_str(),
            e.predicted ? ", predicted" : "");
    }
}

void registerPopping(CLI::App& app) {
    auto a = std::make_shared<PoppingCommand>();
    CLI::App* cmd = app.add_subcommand(
        "popping", "find and prove popping: sweep views with both splatters and the reference");
    addVolumeOptions(*cmd, a->volume);
    addRenderOptions(*cmd, a->render, false);
    addPoppingOptions(*cmd, a->popping);
    addTableOption(*cmd, "report", a->report, kPoppingOptions);
    addTableOption(*cmd, "resume", a->resume, kPoppingOptions);
    addTableOption(*cmd, "quiet", a->quiet, kPoppingOptions);
    addSequenceBrickOptions(*cmd, a->brick, kPoppingOptions);
    cmd->footer(
        "Examples:\n"
        "  splat popping synthetic:phantom:64 --from 40 --to 50 --step 0.5 --report pop\n"
        "  splat popping ch2.nii.gz --tf mri-head --renderers axis,sheet --no-flip --report pop");
    cmd->callback([a, cmd] {
        prepareCommand(*cmd, {"volume", "report"});
        if (isGaussianScene(a->volume.spec))
            return runGaussianPopping(*cmd, a->render, a->popping, a->volume.spec, a->report,
                                      a->quiet, a->resume);
        if (given(*cmd, "renderer") && !fromScene(*cmd, "renderer"))
            warn("--renderer does not apply to popping (it compares --renderers); ignored");
        RenderUse use;
        use.oneRenderer = false;
        RenderSettings settings = settingsFromArgs(a->render, use);
        Sweep sweep;
        PoppingOptions o;
        poppingFromArgs(*cmd, a->popping, settings, sweep, o);
        loadOptionsFromArgs(a->volume);
        // The Scene is validated against its first renderer (iso: the reference alone).
        settings.renderer = o.renderers.front();
        checkSequenceBrickOptions(*cmd, a->brick);
        // Bricks, or frames in parallel under mpirun (docs/parallel.md,
        // chooseSequenceBricks); each renderer holds its own Scenes of the same samples.
        const SequenceBricks choice =
            chooseSequenceBricks(a->volume, settings, a->brick.bricks, a->brick.rankMemory,
                                 poppingSampleBytes(o.renderers));
        const int bricks = choice.bricks;
        const std::optional<Volume>& geometry = choice.geometry;
        const bool alone = choice.alone;
        const bool bricked = bricks > 0;
        if (bricked && o.truth == Truth::Point && settings.quality.pixelFilter > 0)
            throw UsageError(
                "popping in bricks with --truth point: --pixel-filter would filter the bricks' "
                "reference too (leave one out)");
        // The Scene's settings carry the reference's pixel filter that --truth asks for
        // (splat/popping.h poppingSettings), so that the sweep renders views in parallel.
        auto judged = [&](const RenderSettings& s, const Volume& v) {
            Sweep views = sweep;
            views.base = s.camera;
            return poppingSettings(s, v, poppingViews(a->popping, views), o.truth);
        };
        if (!bricked && workerProcess())  // under mpirun: render the frames rank 0 asks for
            return serveFrames([&] {
                auto v = std::make_shared<const Volume>(loadVolumeFromArgs(a->volume));
                return Scene(v, judged(withDataDefaults(a->render, settings, *v), *v));
            });
        const bool sheet = std::find(o.renderers.begin(), o.renderers.end(), RendererKind::Sheet) !=
                           o.renderers.end();
        if (given(*cmd, "brick-composite") && !fromScene(*cmd, "brick-composite") &&
            (!bricked || !sheet))
            warn(
                "--brick-composite applies to popping in bricks (--bricks, or a volume beyond "
                "--rank-memory) with the image-aligned splatter (sheet): ignored");
        else if (bricked && sheet && a->brick.composite == "fast")
            warn(
                "--brick-composite fast: the image-aligned splatter is approximate where its "
                "slabs cross a brick face, so its findings may change with the bricks ("
                "docs/parallel.md); --brick-composite exact is not");
        if (bricked && !alone)
            warn(a->volume.spec +
                 ": its samples are not read by brick (DICOM, a slice folder, NRRD text or hex, "
                 "an ANALYZE pair): every rank loads the whole volume once and keeps its brick");
        // docs/parallel.md: in bricks every rank loads its bricks and builds their
        // Scenes once (splat/bricks.h BrickedFrames; a brick that cannot be read fails every
        // rank here, before any file is written); rank 0 runs the analysis and asks the group
        // for every frame it needs (bricked_requests.h), the other ranks serve them.
        std::unique_ptr<BrickGroup> group;
        std::unique_ptr<BrickedFrames> frames;
        if (bricked) {
            settings = judged(settings, *geometry);
            group = brickGroup(a->brick.compositor);
            frames = std::make_unique<BrickedFrames>(
                *geometry, brickLoader(a->volume), settings, bricks, *group,
                a->brick.composite == "exact" ? BrickComposite::Exact : BrickComposite::Fast,
                true, brickEmptiness(a->volume));
            settings = frames->settings();
        }
        std::optional<BrickedFrameRequests> requests;
        if (bricked) requests.emplace(*frames, *group);
        if (workerProcess()) {
            if (requests->serve()) group->gather(frames->stats());
            return;
        }
        beginRun(*cmd);
        // The frames rendered so far are journaled, so that --resume after an interruption
        // renders only the rest; the journal goes once the report is written.
        const std::string journal = a->report + "/.frames";
        prepareJournal(*cmd, journal, a->resume);
        o.frameJournal = journal;
        std::shared_ptr<const Volume> volume;
        std::optional<Scene> scene;
        if (bricked) {
            o.renderFrame = [&](const RenderSettings& s, RenderStats* st) {
                return requests->render(s.camera, s.renderer, st);
            };
        } else {
            volume = std::make_shared<const Volume>(loadVolumeFromArgs(a->volume));
            settings = judged(withDataDefaults(a->render, settings, *volume), *volume);
            scene.emplace(volume, settings);
        }
        installInterruptHandler();
        ProgressReporter progress("frames", a->quiet);
        o.progress = [&](std::size_t d, std::size_t t, const std::string& w) {
            return progress(d, t, w);
        };
        PoppingResult result;
        try {
            if (a->popping.path().empty()) {
                result = bricked ? analyzePopping(*geometry, settings, sweep, o)
                                 : analyzePopping(*scene, sweep, o);
            } else {
                const CameraPath path = CameraPath::fromJson(
                    a->popping.path(), bricked ? settings.camera : scene->settings().camera,
                    a->popping.frames());
                result = bricked ? analyzePopping(*geometry, settings, path, o)
                                 : analyzePopping(*scene, path, o);
            }
        } catch (const Cancelled&) {
            progress.finish();
            throw Error(
                "interrupted: no report written (--resume finishes it from the frames "
                "rendered)");
        }
        progress.finish();
        std::vector<BrickStats> ranks;
        if (bricked) {
            requests->end(true);
            ranks = group->gather(frames->stats());
        }
        writePoppingReport(result, a->report, commandLine());
        removeJournal(journal);
        printPoppingSummary(result);
        if (!a->quiet) printRankStats(ranks, requests->frames(), "");
        std::printf("wrote %s/report.html, metrics.csv, summary.json (%.1f s)\n", a->report.c_str(),
                    result.totalMs / 1000.0);
        finishRun(*cmd);
    });
}

}  // namespace splat::cli
