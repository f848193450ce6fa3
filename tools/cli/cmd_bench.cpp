// `splat bench VOLUME [options] --json FILE`: times frames (median of repeats) for the
// chosen renderer at several thread counts, and reports footprint-pixel throughput.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "commands.h"
#include "diagnostics.h"
#include "render_options.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "volume_options.h"

namespace splat::cli {

namespace {
struct BenchCommand {
    VolumeArgs volume;
    RenderArgs render;
    std::string json, threadList = "1,2";
    int repeats = 5;
};

std::vector<int> parseThreads(const std::string& text) {
    std::vector<int> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        try {
            v.push_back(std::stoi(item));
        } catch (const std::exception&) {
            throw Error("--thread-list '" + text + "' must be comma-separated integers");
        }
        if (v.back() < 1 || v.back() > 1024) throw Error("--thread-list entries must be 1..1024");
    }
    if (v.empty()) throw Error("--thread-list is empty");
    return v;
}
}  // namespace

void registerBench(CLI::App& app) {
    auto a = std::make_shared<BenchCommand>();
    CLI::App* cmd =
        app.add_subcommand("bench", "time rendering (median of repeats) per thread count");
    addVolumeOptions(*cmd, a->volume);
    addRenderOptions(*cmd, a->render, false);
    addTableOption(*cmd, "repeats", a->repeats, kBenchOptions);
    addTableOption(*cmd, "thread-list", a->threadList, kBenchOptions);
    addTableOption(*cmd, "json", a->json, kBenchOptions);
    cmd->footer(
        "Examples:\n"
        "  splat bench synthetic:phantom:64 --renderer sheet --thread-list 1,2,4\n"
        "  splat bench ch2.nii.gz --tf mri-head --size 1024x1024 --repeats 9 --json b.json");
    cmd->callback([a, cmd] {
        prepareCommand(*cmd, {"volume"});
        const std::vector<int> threads = asUsage([&] {
            if (a->repeats < 1 || a->repeats > 1000)
                throw Error("--repeats must be between 1 and 1000");
            return parseThreads(a->threadList);
        });
        if (!a->json.empty()) checkOutputFile(a->json, "--json");  // before the timing
        RenderSettings settings = settingsFromArgs(a->render, RenderUse{});
        loadOptionsFromArgs(a->volume);
        chooseZarrLevel(a->volume, settings);
        beginRun(*cmd);
        const Volume volume = loadVolumeFromArgs(a->volume);
        settings = withDataDefaults(a->render, settings, volume);
        nlohmann::json out;
        out["volume"] = a->volume.spec;
        out["renderer"] = toString(settings.renderer);
        out["mode"] = toString(settings.mode);
        out["size"] = a->render.size();
        out["slab"] = settings.quality.slab;
        out["hardware_threads"] = std::thread::hardware_concurrency();
        out["scene"] = sceneOf(*cmd);
        std::printf("%-8s %-7s %8s %10s %10s %12s %14s\n", "threads", "renderer", "splats",
                    "median ms", "min ms", "fp px/frame", "fp px/s");
        for (int t : threads) {
            settings.threads = t;
            const Renderer renderer(volume, settings);
            renderer.render();  // warm-up
            std::vector<double> ms;
            RenderStats stats;
            for (int r = 0; r < a->repeats; ++r) {
                renderer.render(&stats);
                ms.push_back(stats.milliseconds);
            }
            std::sort(ms.begin(), ms.end());
            const double median = ms[ms.size() / 2];
            const double rate = double(stats.footprintPixels) / (median * 1e-3);
            std::printf("%-8d %-7s %8zu %10.1f %10.1f %12zu %14.3g\n", t,
                        toString(settings.renderer), stats.splats, median, ms.front(),
                        stats.footprintPixels, rate);
            out["runs"].push_back({{"threads", t},
                                   {"median_ms", median},
                                   {"min_ms", ms.front()},
                                   {"splats", stats.splats},
                                   {"voxels", stats.voxels},
                                   {"footprint_pixels", stats.footprintPixels},
                                   {"footprint_pixels_per_s", rate},
                                   {"sheets", stats.sheets},
                                   {"culled", stats.culledSplats},
                                   {"lod_level", stats.lodLevel},
                                   {"lod_splats", stats.lodSplats},
                                   {"lod_level_splats", stats.lodLevelSplats},
                                   {"project_ms", stats.projectMs},
                                   {"bin_ms", stats.binMs},
                                   {"tiles_ms", stats.tilesMs}});
        }
        if (!a->json.empty()) writeTextAtomic(a->json, out.dump(2) + "\n");
        finishRun(*cmd);
    });
}

}  // namespace splat::cli
