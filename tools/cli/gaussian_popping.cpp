// `splat popping` of a Gaussian scene (gaussian_scenes.h): the popping analysis with the
// Gaussian renderers (splat/gaussian_popping.h), the report and the summary as for a volume.
#include "splat/gaussian_popping.h"

#include <cstdio>

#include "commands.h"
#include "diagnostics.h"
#include "gaussian_scenes.h"
#include "progress.h"
#include "resume_journal.h"
#include "scene_file.h"
#include "splat/error.h"

namespace splat::cli {

namespace {

/// --renderers of a Gaussian scene (default all four); a usage error names the renderers.
std::vector<GaussianRenderer> gaussianRenderersOf(const CLI::App& cmd, const PoppingArgs& a) {
    const std::string list =
        given(cmd, "renderers") ? a.values.text("renderers") : "3dgs,3dgs-pixel,sheet,reference";
    return asUsage([&] { return parseGaussianRenderers(list); });
}

}  // namespace

void runGaussianPopping(const CLI::App& cmd, const RenderArgs& render, PoppingArgs& popping,
                        const std::string& spec, const std::string& report, bool quiet,
                        bool resume) {
    if (given(cmd, "renderer") && !fromScene(cmd, "renderer"))
        warn("--renderer does not apply to popping (it compares --renderers); ignored");
    if (given(cmd, "truth") && !fromScene(cmd, "truth"))
        warn(
            "--truth does not apply to Gaussian scenes (their reference is point-sampled); "
            "ignored");
    const RenderSettings view = gaussianViewOf(render);
    const std::vector<GaussianRenderer> renderers = gaussianRenderersOf(cmd, popping);
    popping.values.set("renderers", "axis");  // the volume renderers' check passes
    Sweep sweep;
    PoppingOptions o;
    poppingFromArgs(cmd, popping, view, sweep, o);
    const GaussianRenderOptions g = gaussianRenderOptions(cmd, render, view);
    const GaussianScene scene = openGaussians(spec);
    beginRun(cmd);
    const std::string journal = report + "/.frames";
    prepareJournal(cmd, journal, resume);
    o.frameJournal = journal;
    installInterruptHandler();
    ProgressReporter progress("frames", quiet);
    o.progress = [&](std::size_t d, std::size_t t, const std::string& w) {
        return progress(d, t, w);
    };
    PoppingResult result;
    try {
        result =
            popping.path().empty()
                ? analyzeGaussianPopping(scene, sweep, renderers, g, o)
                : analyzeGaussianPopping(
                      scene, CameraPath::fromJson(popping.path(), view.camera, popping.frames()),
                      renderers, g, o);
    } catch (const Cancelled&) {
        progress.finish();
        throw Error(
            "interrupted: no report written (--resume finishes it from the frames rendered)");
    }
    progress.finish();
    writePoppingReport(result, report, commandLine());
    removeJournal(journal);
    printPoppingSummary(result);
    std::printf("wrote %s/report.html, metrics.csv, summary.json (%.1f s)\n", report.c_str(),
                result.totalMs / 1000.0);
    finishRun(cmd);
}

}  // namespace splat::cli
