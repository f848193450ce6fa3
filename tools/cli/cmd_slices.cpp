// `splat slices VOLUME --axis z [--every N] -o DIR`: axis-aligned slices through voxel centres
// (the reconstructed field), one image per slice and a mosaic of them all.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.h"
#include "diagnostics.h"
#include "scene_file.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "view_options.h"
#include "volume_options.h"

namespace splat::cli {

namespace {
struct SlicesCommand {
    VolumeArgs volume;
    ViewArgs view;
    std::string axis = "z", output, format = "png";
    int every = 1, columns = 0;
};
}  // namespace

void registerSlices(CLI::App& app) {
    auto a = std::make_shared<SlicesCommand>();
    CLI::App* cmd = app.add_subcommand("slices", "slices as images plus a mosaic");
    addVolumeOptions(*cmd, a->volume);
    addViewOptions(*cmd, a->view);
    addTableOption(*cmd, "axis", a->axis, kSlicesOptions);
    addTableOption(*cmd, "every", a->every, kSlicesOptions);
    addTableOption(*cmd, "columns", a->columns, kSlicesOptions);
    addTableOption(*cmd, "format", a->format, kSlicesOptions);
    addTableOption(*cmd, "output", a->output, kSlicesOptions)->required();
    cmd->footer(
        "Examples:\n"
        "  splat slices ch2.nii.gz --axis z --every 4 -o slices\n"
        "  splat slices ct.nrrd --axis y --window-preset ct-bone --format exr -o cor");
    cmd->callback([a, cmd] {
        prepareCommand(*cmd, {"volume"});
        const int axis = a->axis == "x" ? 0 : a->axis == "y" ? 1 : a->axis == "z" ? 2 : -1;
        asUsage([&] {
            if (axis < 0) throw Error("--axis must be x, y or z");
            if (a->every < 1) throw Error("--every must be >= 1");
            if (a->columns < 0 || a->columns > 100000)
                throw Error("--columns must be between 0 and 100000");
            if (a->format != "png" && a->format != "exr" && a->format != "tif")
                throw Error("--format must be png, exr or tif");
        });
        checkViewArgs(a->view);
        loadOptionsFromArgs(a->volume);
        beginRun(*cmd);
        namespace fs = std::filesystem;
        std::error_code ec;
        fs::create_directories(a->output, ec);
        if (!fs::is_directory(a->output)) throw Error(a->output + ": cannot create the folder");
        const Volume volume = loadVolumeFromArgs(a->volume);
        const FieldView field(volume, a->view.kernel, a->view.sigma, a->view.radius,
                              a->view.threads);
        std::vector<Image> slices;
        PlaneView plane;
        for (int k = 0; k < volume.dims[axis]; k += a->every) {
            plane = slicePlane(volume, axis, k);
            slices.push_back(multiplanarReconstruction(field, plane));
            char name[64];
            std::snprintf(name, sizeof name, "slice_%c%04d.%s", "xyz"[axis], k,
                          a -> format.c_str());
            writeView((fs::path(a->output) / name).string(), slices.back(), a->view, volume,
                      plane.pixelSize);
        }
        const int n = int(slices.size());
        const int cols = a->columns > 0 ? a->columns : int(std::ceil(std::sqrt(double(n))));
        const int rows = (n + cols - 1) / cols;
        const int w = slices[0].width, h = slices[0].height;
        const VolumeStats st = volumeStats(volume, 1);
        Image mosaic(cols * w, rows * h);
        for (auto& p : mosaic.pixels) p = glm::vec4(glm::vec3(st.minValue), 1.0f);
        for (int s = 0; s < n; ++s)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    mosaic.at((s % cols) * w + x, (s / cols) * h + y) = slices[s].at(x, y);
        const std::string mosaicPath = (fs::path(a->output) / ("mosaic." + a->format)).string();
        writeView(mosaicPath, mosaic, a->view, volume, plane.pixelSize);
        std::printf("wrote %d slices along %c and %s (%dx%d)\n", n, "xyz"[axis], mosaicPath.c_str(),
                    cols, rows);
    });
}

}  // namespace splat::cli
