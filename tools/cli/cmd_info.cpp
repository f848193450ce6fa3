// `splat info VOLUME`: loads the volume and prints describeVolume().
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.h"
#include "diagnostics.h"
#include "gaussian_scenes.h"
#include "splat/gaussians.h"
#include "scene_file.h"
#include "splat/sparse_files.h"
#include "volume_options.h"

namespace splat::cli {
namespace {

std::string triple(const glm::dvec3& v, const char* sep) {
    char text[96];
    std::snprintf(text, sizeof text, "%g%s%g%s%g", v.x, sep, v.y, sep, v.z);
    return text;
}

/// The grids of an OpenVDB file, the levels of an OME-Zarr image (nothing for other files).
void describeSparseFile(const std::string& spec) {
    if (isZarrFolder(spec)) {
        const ZarrImageInfo z = describeZarr(spec);
        std::printf("OME-Zarr:    axes %s, %d time point%s, %d channel%s, %zu level%s\n",
                    z.axes.c_str(), z.times, z.times == 1 ? "" : "s", z.channels,
                    z.channels == 1 ? "" : "s", z.levels.size(), z.levels.size() == 1 ? "" : "s");
        for (std::size_t l = 0; l < z.levels.size(); ++l) {
            const ZarrLevelInfo& L = z.levels[l];
            std::string chunks;
            for (auto c : L.chunks) chunks += (chunks.empty() ? "" : "x") + std::to_string(c);
            std::printf("  level %zu '%s': %d x %d x %d, spacing %s, origin %s, chunks %s, %s %s\n",
                        l, L.path.c_str(), L.dims.x, L.dims.y, L.dims.z,
                        triple(L.spacing, " x ").c_str(), triple(L.origin, ", ").c_str(),
                        chunks.c_str(), L.dtype.c_str(), L.compressor.c_str());
        }
        return;
    }
    const std::filesystem::path p(spec);
    std::string ext = p.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".vdb") return;
    const auto grids = listVdbGrids(spec);
    std::printf("OpenVDB:     %zu grid%s\n", grids.size(), grids.size() == 1 ? "" : "s");
    for (const VdbGridInfo& g : grids) {
        std::printf("  '%s' %s: %llu active voxels", g.name.c_str(), g.valueType.c_str(),
                    static_cast<unsigned long long>(g.activeVoxels));
        if (g.bboxMax.x >= g.bboxMin.x)
            std::printf(", bbox (%d, %d, %d)-(%d, %d, %d)", g.bboxMin.x, g.bboxMin.y, g.bboxMin.z,
                        g.bboxMax.x, g.bboxMax.y, g.bboxMax.z);
        if (g.valueType == "float" || g.valueType == "double")
            std::printf(", background %g", g.background);
        std::printf(", voxel %s%s\n", triple(g.voxelSize, " x ").c_str(),
                    g.axisAligned ? "" : " (not axis-aligned: not loadable)");
    }
}

}  // namespace

void registerInfo(CLI::App& app) {
    auto args = std::make_shared<VolumeArgs>();
    CLI::App* cmd = app.add_subcommand(
        "info", "print a volume's size, spacing, extent, value range and histogram");
    addVolumeOptions(*cmd, *args);
    cmd->footer(
        "Examples:\n"
        "  splat info ch2.nii.gz\n"
        "  splat info smoke.vdb --grid density\n"
        "  splat info scan.raw --dims 256x256x128 --type uint16 --big-endian --spacing 1,1,2");
    cmd->callback([args, cmd] {
        prepareCommand(*cmd, {"volume"});
        if (isGaussianScene(args->spec)) {
            printGaussianInfo(args->spec);
            return;
        }
        loadOptionsFromArgs(*args);
        // A folder of several DICOM series: list them (one is chosen with --series UID).
        if (args->values.text("series").empty()) {
            const auto series = listDicomSeries(args->spec);
            if (series.size() > 1) {
                std::printf("%s: %zu DICOM series (load one with --series UID)\n",
                            args->spec.c_str(), series.size());
                for (const auto& s : series)
                    std::printf("  %s  #%d %s %s, %zu files of %d x %d\n", s.uid.c_str(),
                                s.seriesNumber, s.modality.c_str(),
                                s.description.empty() ? "(no description)"
                                                      : ("'" + s.description + "'").c_str(),
                                s.files, s.columns, s.rows);
                return;
            }
        }
        Volume v = loadVolumeFromArgs(*args);
        std::fputs(describeVolume(v).c_str(), stdout);
        describeSparseFile(args->spec);
    });
}

}  // namespace splat::cli
