// `splat study VOLUME [render options] --sweep KNOB=V1,V2,... [--sweep ...] --report DIR
// [--repeats N] [--warmup N] [--views AZ:EL,...] [--convergence]`: the speed-accuracy
// study of splat/study.h: every combination of the swept knobs, timed and compared with
// the reference; Pareto-optimal settings marked; study.csv, study.json, pareto.svg and
// pareto.png in DIR, the reference cached there.
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "commands.h"
#include "diagnostics.h"
#include "parallel.h"
#include "progress.h"
#include "render_options.h"
#include "resume_journal.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/study.h"
#include "volume_options.h"

namespace splat::cli {

namespace {
struct StudyCommand {
    VolumeArgs volume;
    RenderArgs render;
    std::vector<std::string> sweeps;
    std::string report, views;
    int repeats = 5, warmup = 1;
    double truthStep = 0.125, truthTolerance = 1e-5, ppd = 67;
    std::string truth = "auto";
    bool convergence = false, quiet = false, resume = false, noPresets = false;
};

std::vector<glm::dvec2> parseViews(const std::string& text) {
    std::vector<glm::dvec2> out;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        const auto colon = item.find(':');
        try {
            if (colon == std::string::npos)
                out.emplace_back(std::stod(item), 0.0);
            else
                out.emplace_back(std::stod(item.substr(0, colon)),
                                 std::stod(item.substr(colon + 1)));
        } catch (const std::exception&) {
            throw Error("--views '" + text + "' must look like AZ[:EL],AZ[:EL],...");
        }
    }
    return out;
}

void printTable(const StudyResult& r) {
    std::printf("%-40s %10s %8s %10s %10s %9s %8s %9s %s\n", "setting", "ms/frame", "spread",
                "peak MiB", "rmse", "psnr", "max", "flip", "pareto");
    for (const StudyPoint& p : r.points)
        std::printf("%-40s %10.2f %8.2f %10.1f %10.3g %9.2f %8.3g %9.4f %s\n", p.label().c_str(),
                    p.msMedian, p.msMad, p.peakMiB, p.rmse, p.psnr, p.maxAbs, p.flip,
                    p.pareto ? "*" : "");
    for (const ConvergenceSeries& c : r.convergence) {
        std::printf("convergence %-15s %-9s order %.2f  (", c.parameter.c_str(),
                    toString(c.renderer), c.order);
        for (std::size_t i = 0; i < c.h.size(); ++i)
            std::printf("%sh=%.4g: %.3g", i ? ", " : "", c.h[i], c.error[i]);
        std::printf(")\n");
    }
}
}  // namespace

void registerStudy(CLI::App& app) {
    auto a = std::make_shared<StudyCommand>();
    CLI::App* cmd = app.add_subcommand(
        "study", "speed vs accuracy: sweep quality knobs, time them, compare with the reference");
    addVolumeOptions(*cmd, a->volume);
    addRenderOptions(*cmd, a->render, false);
    constexpr unsigned S = kStudyOptions;
    addTableOption(*cmd, "sweep", a->sweeps, S);
    addTableOption(*cmd, "repeats", a->repeats, S);
    addTableOption(*cmd, "warmup", a->warmup, S);
    addTableOption(*cmd, "views", a->views, S);
    addTableOption(*cmd, "truth-step", a->truthStep, S);
    addTableOption(*cmd, "truth-tolerance", a->truthTolerance, S);
    addTableOption(*cmd, "truth", a->truth, S);
    addTableOption(*cmd, "ppd", a->ppd, S);
    addTableOption(*cmd, "no-presets", a->noPresets, S);
    addTableOption(*cmd, "convergence", a->convergence, S);
    addTableOption(*cmd, "report", a->report, S);
    addTableOption(*cmd, "resume", a->resume, S);
    addTableOption(*cmd, "quiet", a->quiet, S);
    cmd->footer(
        "Examples:\n"
        "  splat study synthetic:phantom:48 --sweep renderer=axis,sheet --sweep slab=0.5,1,2 "
        "--report st\n"
        "  splat study ch2.nii.gz --tf mri-head --views 0,45:30 --convergence --report st");
    cmd->callback([a, cmd] {
        prepareCommand(*cmd, {"volume", "report"});
        RenderUse use;
        use.oneRenderer = false;
        RenderSettings settings = settingsFromArgs(a->render, use);
        StudyOptions o;
        asUsage([&] {
            for (const auto& s : a->sweeps) o.sweeps.push_back(parseKnob(s));
            if (!a->views.empty()) o.views = parseViews(a->views);
            if (a->repeats < 1 || a->repeats > 1000 || a->warmup < 0 || a->warmup > 1000)
                throw Error("--repeats must be 1..1000, --warmup 0..1000");
            if (!std::isfinite(a->truthStep) || !(a->truthStep >= 1e-3) || a->truthStep > 64 ||
                !std::isfinite(a->truthTolerance) || !(a->truthTolerance > 0) ||
                !std::isfinite(a->ppd) || !(a->ppd > 0))
                throw Error(
                    "--truth-step must be in [0.001, 64], --truth-tolerance and --ppd finite and "
                    "> 0");
            o.truth = parseTruth(a->truth);
        });
        loadOptionsFromArgs(a->volume);
        o.repeats = a->repeats;
        o.warmup = a->warmup;
        o.referenceStep = a->truthStep;
        o.referenceTolerance = a->truthTolerance;
        o.pixelsPerDegree = a->ppd;
        o.presets = !a->noPresets;
        if (workerProcess())  // under mpirun: render the references rank 0 asks for (parallel.h)
            return serveFrames([&] {
                auto v = std::make_shared<const Volume>(loadVolumeFromArgs(a->volume));
                const RenderSettings base = withDataDefaults(a->render, settings, *v);
                return Scene(v, studyReferenceSettings(base, o, base.camera));
            });
        o.cacheDir = a->report + "/cache";
        removeStaleTemporaries(o.cacheDir);  // left by a killed run
        beginRun(*cmd);
        // The points measured so far are journaled, so that --resume after an interruption
        // measures only the rest; the journal goes once the report is written.
        const std::string journal = a->report + "/.points";
        prepareJournal(*cmd, journal, a->resume);
        o.pointJournal = journal + "/points.json";
        auto volume = std::make_shared<const Volume>(loadVolumeFromArgs(a->volume));
        settings = withDataDefaults(a->render, settings, *volume);
        installInterruptHandler();
        ProgressReporter progress("frames", a->quiet);
        o.progress = [&](std::size_t d, std::size_t t, const std::string& w) {
            return progress(d, t, w);
        };
        StudyResult result;
        try {
            result = runStudy(volume, settings, o);
            if (a->convergence) {
                ConvergenceOptions co;
                co.progress = o.progress;
                result.convergence = studyConvergence(volume, settings, co);
            }
        } catch (const Cancelled&) {
            progress.finish();
            throw Error(
                "interrupted: no report written (--resume finishes it from the points "
                "measured)");
        }
        progress.finish();
        writeStudyReport(result, a->report, commandLine());
        removeJournal(journal);
        printTable(result);
        std::printf("wrote %s/study.csv, study.json, pareto.svg, pareto.png (%.1f s)\n",
                    a->report.c_str(), result.totalMs / 1000.0);
        finishRun(*cmd);
    });
}

}  // namespace splat::cli
