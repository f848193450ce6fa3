// `splat mpr VOLUME --plane X,Y,Z,NX,NY,NZ [--up V] --size WxH --pixel-size S -o OUT`:
// multiplanar reconstruction (axis-aligned or oblique) through the reconstructed field.
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "diagnostics.h"
#include "render_options.h"
#include "scene_file.h"
#include "splat/error.h"
#include "splat/options.h"
#include "view_options.h"
#include "volume_options.h"

namespace splat::cli {

namespace {
struct MprCommand {
    VolumeArgs volume;
    ViewArgs view;
    std::string plane, up = "auto", size = "256x256", output;
    double pixelSize = 0;
};
}  // namespace

void registerMpr(CLI::App& app) {
    auto a = std::make_shared<MprCommand>();
    CLI::App* cmd = app.add_subcommand("mpr", "a cut plane through the reconstructed field");
    addVolumeOptions(*cmd, a->volume);
    addViewOptions(*cmd, a->view);
    addTableOption(*cmd, "plane", a->plane, kMprOptions)->required();
    addTableOption(*cmd, "up", a->up, kMprOptions);
    addTableOption(*cmd, "size", a->size, kMprOptions);
    addTableOption(*cmd, "pixel-size", a->pixelSize, kMprOptions);
    addTableOption(*cmd, "output", a->output, kMprOptions)->required();
    cmd->footer(
        "Examples:\n"
        "  splat mpr ch2.nii.gz --plane 0,0,10,0,0,1 --size 256x256 -o axial.png\n"
        "  splat mpr ct.nrrd --plane 0,0,0,1,1,0 --window-preset ct-bone -o oblique.png");
    cmd->callback([a, cmd] {
        prepareCommand(*cmd, {"volume"});
        checkImageOutput(a->output);
        checkViewArgs(a->view);
        const std::vector<double> p = asUsage([&] {
            const std::vector<double> v = parseNumbers(a->plane, "--plane");
            if (v.size() != 6 || (v[3] == 0 && v[4] == 0 && v[5] == 0))
                throw Error("--plane needs X,Y,Z,NX,NY,NZ with a non-zero normal");
            if (a->up != "auto") parseVec3(a->up, "--up");
            parseSize(a->size, "--size");
            if (!std::isfinite(a->pixelSize) || a->pixelSize < 0)
                throw Error("--pixel-size must be a finite number >= 0");
            return v;
        });
        loadOptionsFromArgs(a->volume);
        beginRun(*cmd);
        const Volume volume = loadVolumeFromArgs(a->volume);
        PlaneView plane;
        plane.point = {p[0], p[1], p[2]};
        plane.normal = {p[3], p[4], p[5]};
        if (a->up == "auto") {
            const glm::dvec3 n = glm::normalize(plane.normal);
            plane.up = std::abs(n.z) > 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
        } else {
            plane.up = parseVec3(a->up, "--up");
        }
        const glm::ivec2 size = parseSize(a->size, "--size");
        plane.width = size.x;
        plane.height = size.y;
        plane.pixelSize = a->pixelSize > 0 ? a->pixelSize : volume.minSpacing();
        const FieldView field(volume, a->view.kernel, a->view.sigma, a->view.radius,
                              a->view.threads);
        writeView(a->output, multiplanarReconstruction(field, plane), a->view, volume,
                  plane.pixelSize);
        std::printf("wrote %s: %dx%d, %.3f per pixel\n", a->output.c_str(), plane.width,
                    plane.height, plane.pixelSize);
    });
}

}  // namespace splat::cli
