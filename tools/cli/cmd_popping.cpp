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
#include "commands.h"
#include "diagnostics.h"
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
struct PoppingCommand {
    VolumeArgs volume;
    RenderArgs render;
    PoppingArgs popping;
    std::string report;
    int bricks = 0;
    bool quiet = false, resume = false;
};

void printSummary(const PoppingResult& r) {
    std::printf("%-10s %12s %12s %10s %8s %12s\n", "renderer", "spike ratio", "median T", "flicker",
                "events", "ms/frame");
    for (const RendererSeries& s : r.series) {
        int events = 0;
        for (const PoppingEvent& e : r.events) events += e.renderer == s.renderer;
        std::printf("%-10s %12.2f %12.3g %10.2f %8d %12.1f\n", toString(s.renderer), s.spikeRatio,
                    s.medianT, s.flickerRatio, events, s.msPerFrame);
    }
    for (const RendererSeries& s : r.series) {
        std::size_t exact = 0;
        for (std::size_t p : s.exactPixels) exact += p > 0;
        if (exact > 0)
            warn(std::string(toString(s.renderer)) + ": " + std::to_string(exact) + " of " +
                 std::to_string(s.exactPixels.size()) +
                 " views handed to the exact path (the reference's pixels): " + s.exactReason);
    }
    // Positions: degrees of a sweep, or view positions of a camera path.
    const char* unit = r.pathViews > 0 ? " (path position)" : " degrees";
    for (double a : r.predictedSwitches) std::printf("predicted sheet switch at %.6f%s\n", a, unit);
    for (const PoppingEvent& e : r.events)
        std::printf(
            "event (%s) %.4g..%.4g: signal %.3g; refined to %.3g%s at %.6f: jump "
            "%.3g, slope %.2f (%s); sheet axis %d -> %d%s\n",
            toString(e.renderer), e.angleFrom, e.angleTo, e.signal, e.refinedWidth, unit,
            e.refinedAngle, e.refinedJump, e.refinedSlope,
            std::abs(e.refinedSlope) < 0.25 ? "a discontinuity" : "continuous change",
            e.sheetAxisBefore, e.sheetAxisAfter, e.predicted ? ", predicted" : "");
}
}  // namespace

void registerPopping(CLI::App& app) {
    auto a = std::make_shared<PoppingCommand>();
    CLI::App* cmd = app.add_subcommand(
        "popping", "find and prove popping: sweep views with both splatters and the reference");
    addVolumeOptions(*cmd, a->volume);
    addRenderOptions(*cmd, a->render, false);
    addPoppingOptions(*cmd, a->popping);
    const std::string out = "Output";
    addOption(*cmd, "--report", a->report, "report folder (report.html, metrics.csv, summary.json)",
              out, PathKind::Output);
    addFlag(*cmd, "--resume", a->resume,
            "finish an interrupted run: reuse the frames it left in REPORT/.frames", out);
    addFlag(*cmd, "-q,--quiet", a->quiet, "no progress output", out);
    addOption(*cmd, "--bricks", a->bricks,
              "sort-last, one process: cut the volume into K bricks, loaded and built once, "
              "every frame rendered by them and composited (0: off; exact sheets)",
              out);
    cmd->footer(
        "Examples:\n"
        "  splat popping synthetic:phantom:64 --from 40 --to 50 --step 0.5 --report pop\n"
        "  splat popping ch2.nii.gz --tf mri-head --renderers axis,sheet --no-flip --report pop");
    cmd->callback([a, cmd] {
        prepareCommand(*cmd, {"volume", "report"});
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
        if (a->bricks < 0 || a->bricks > 4096)
            throw UsageError("--bricks must be between 0 and 4096");
        if (a->bricks > 0 && processCount() > 1)
            throw UsageError(
                "popping --bricks runs on one process; under mpirun popping is frame-parallel "
                "(leave out --bricks)");
        if (a->bricks > 0 && o.truth == Truth::Point && settings.quality.pixelFilter > 0)
            throw UsageError(
                "popping --bricks --truth point: --pixel-filter would filter the bricks' "
                "reference too (leave one out)");
        // The Scene's settings carry the reference's pixel filter that --truth asks for
        // (splat/popping.h poppingSettings), so that the sweep renders views in parallel.
        auto judged = [&](const RenderSettings& s, const Volume& v) {
            Sweep views = sweep;
            views.base = s.camera;
            return poppingSettings(s, v, poppingViews(a->popping, views), o.truth);
        };
        if (workerProcess())  // under mpirun: render the frames rank 0 asks for (parallel.h)
            return serveFrames([&] {
                auto v = std::make_shared<const Volume>(loadVolumeFromArgs(a->volume));
                return Scene(v, judged(withDataDefaults(a->render, settings, *v), *v));
            });
        beginRun(*cmd);
        // The frames rendered so far are journaled, so that --resume after an interruption
        // renders only the rest; the journal goes once the report is written.
        const std::string journal = a->report + "/.frames";
        prepareJournal(*cmd, journal, a->resume);
        o.frameJournal = journal;
        // README "Beyond one machine": --bricks renders every frame from bricks whose Scenes
        // are built once (splat/bricks.h BrickedFrames), through the analyser's frame seam.
        std::shared_ptr<const Volume> volume;
        std::optional<Scene> scene;
        std::optional<Volume> geometry;
        std::unique_ptr<BrickGroup> group;
        std::unique_ptr<BrickedFrames> bricked;
        if (a->bricks > 0) {
            geometry = brickedGeometry(a->volume);
            settings = judged(withFreeCameraTarget(settings, *geometry), *geometry);
            group = brickGroup();
            bricked = std::make_unique<BrickedFrames>(*geometry, brickLoader(a->volume), settings,
                                                      a->bricks, *group);
            o.renderFrame = [&](const RenderSettings& s, RenderStats* st) {
                return bricked->render(s.camera, s.renderer, st);
            };
            settings = bricked->settings();
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
            if (bricked && !a->popping.path.empty())
                throw Error("popping --bricks takes a sweep (--from, --to, --step), not --path");
            result =
                bricked ? analyzePopping(*geometry, settings, sweep, o)
                : a->popping.path.empty()
                    ? analyzePopping(*scene, sweep, o)
                    : analyzePopping(*scene,
                                     CameraPath::fromJson(a->popping.path, scene->settings().camera,
                                                          a->popping.frames),
                                     o);
        } catch (const Cancelled&) {
            progress.finish();
            throw Error(
                "interrupted: no report written (--resume finishes it from the frames "
                "rendered)");
        }
        progress.finish();
        writePoppingReport(result, a->report, commandLine());
        removeJournal(journal);
        printSummary(result);
        std::printf("wrote %s/report.html, metrics.csv, summary.json (%.1f s)\n", a->report.c_str(),
                    result.totalMs / 1000.0);
        finishRun(*cmd);
    });
}

}  // namespace splat::cli
