// `splat cpr VOLUME --curve FILE.json -o OUT`: straightened curved planar reformation along
// a polyline through the reconstructed field. The curve file:
//   {"points": [[x, y, z], ...], "lateral": [0, 0, 1], "width": 128, "pixel-size": 1}
// (world units; lateral, width and pixel-size optional; flags override them).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "diagnostics.h"
#include "render_options.h"
#include "scene_file.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "view_options.h"
#include "volume_options.h"

namespace splat::cli {

namespace {
struct CprCommand {
    VolumeArgs volume;
    ViewArgs view;
    std::string curve, lateral, output;
    int width = 0;
    double pixelSize = 0;
};
}  // namespace

void registerCpr(CLI::App& app) {
    auto a = std::make_shared<CprCommand>();
    CLI::App* cmd =
        app.add_subcommand("cpr", "curved planar reformation along a polyline (straightened)");
    addVolumeOptions(*cmd, a->volume);
    addViewOptions(*cmd, a->view);
    addTableOption(*cmd, "curve", a->curve, kCprOptions)->required();
    addTableOption(*cmd, "lateral", a->lateral, kCprOptions);
    addTableOption(*cmd, "width", a->width, kCprOptions);
    addTableOption(*cmd, "pixel-size", a->pixelSize, kCprOptions);
    addTableOption(*cmd, "output", a->output, kCprOptions)->required();
    cmd->footer(
        "Examples:\n"
        "  splat cpr ct.nrrd --curve vessel.json -o vessel.png\n"
        "  splat cpr ch2.nii.gz --curve spine.json --width 96 --lateral 1,0,0 -o spine.exr");
    cmd->callback([a, cmd] {
        prepareCommand(*cmd, {"volume"});
        checkImageOutput(a->output);
        checkViewArgs(a->view);
        asUsage([&] {
            if (!a->lateral.empty()) parseVec3(a->lateral, "--lateral");
            if (a->width < 0 || a->width > 32768) throw Error("--width must be 0..32768");
            if (!std::isfinite(a->pixelSize) || a->pixelSize < 0)
                throw Error("--pixel-size must be a finite number >= 0");
        });
        loadOptionsFromArgs(a->volume);
        beginRun(*cmd);
        std::ifstream in(a->curve);
        if (!in) throw Error(a->curve + ": cannot open curve file");
        nlohmann::json j;
        std::vector<glm::dvec3> points;
        glm::dvec3 lateral(0, 0, 1);
        int width = 128;
        double pixelSize = 0;
        try {
            in >> j;
            for (const auto& p : j.at("points")) {
                if (!p.is_array() || p.size() != 3)
                    throw Error(a->curve + ": each point must be [x, y, z]");
                points.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
            }
            if (j.contains("lateral"))
                lateral = {j["lateral"][0].get<double>(), j["lateral"][1].get<double>(),
                           j["lateral"][2].get<double>()};
            width = j.value("width", width);
            pixelSize = j.value("pixel-size", pixelSize);
        } catch (const nlohmann::json::exception& e) {
            throw Error(a->curve + ": bad curve file (" + std::string(e.what()) + ")");
        }
        if (!a->lateral.empty()) lateral = parseVec3(a->lateral, "--lateral");
        if (a->width > 0) width = a->width;
        if (a->pixelSize > 0) pixelSize = a->pixelSize;
        const Volume volume = loadVolumeFromArgs(a->volume);
        if (!(pixelSize > 0)) pixelSize = volume.minSpacing();
        const FieldView field(volume, a->view.kernel, a->view.sigma, a->view.radius,
                              a->view.threads);
        const Image image = curvedPlanarReformation(field, points, lateral, width, pixelSize);
        writeView(a->output, image, a->view, volume, pixelSize);
        std::printf("wrote %s: %dx%d (%zu curve points)\n", a->output.c_str(), image.width,
                    image.height, points.size());
    });
}

}  // namespace splat::cli
