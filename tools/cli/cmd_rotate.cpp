// `splat rotate VOLUME [options] --frames N [--from DEG --to DEG] -o DIR [--gif FILE]`:
// a rotation sequence about the vertical axis (azimuth), frames named frame_0000.png, ...
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.h"
#include "render_options.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "volume_options.h"

namespace splat::cli {

namespace {
struct RotateCommand {
    VolumeArgs volume;
    RenderArgs render;
    std::string outDir, gif, format = "png";
    int frames = 36, fps = 12;
    double from = 0, to = 360;
};

std::string frameName(const std::string& dir, int f, const std::string& ext) {
    char name[64];
    std::snprintf(name, sizeof name, "frame_%04d.%s", f, ext.c_str());
    return (std::filesystem::path(dir) / name).string();
}
}  // namespace

void registerRotate(CLI::App& app) {
    auto a = std::make_shared<RotateCommand>();
    CLI::App* cmd = app.add_subcommand("rotate", "render a rotation sequence (azimuth from..to)");
    addVolumeOptions(*cmd, a->volume);
    addRenderOptions(*cmd, a->render);
    cmd->add_option("--frames", a->frames, "number of frames")->capture_default_str();
    cmd->add_option("--from", a->from, "first azimuth, degrees")->capture_default_str();
    cmd->add_option("--to", a->to, "azimuth after the last frame, degrees (360 closes the loop)")
        ->capture_default_str();
    cmd->add_option("-o,--output", a->outDir, "output folder for the frames (created)")->required();
    cmd->add_option("--format", a->format, "frame format: png, exr or tif")->capture_default_str();
    cmd->add_option("--gif", a->gif, "also write an animated GIF");
    cmd->add_option("--fps", a->fps, "GIF frames per second")->capture_default_str();
    cmd->callback([a] {
        if (a->frames < 1 || a->frames > 100000)
            throw Error("--frames must be between 1 and 100000");
        if (!std::isfinite(a->from) || !std::isfinite(a->to))
            throw Error("--from/--to must be finite");
        if (a->format != "png" && a->format != "exr" && a->format != "tif")
            throw Error("--format must be png, exr or tif");
        if (!a->gif.empty()) {
            // Like the frames folder, the GIF's folder is created if needed.
            const std::filesystem::path parent = std::filesystem::path(a->gif).parent_path();
            std::error_code ec;
            if (!parent.empty() && std::filesystem::path(a->gif).extension() == ".gif")
                std::filesystem::create_directories(parent, ec);
            checkImagePath(a->gif);
        }
        const RenderSettings settings = settingsFromArgs(a->render);
        // The GIF is assembled in memory: keep it under 4 GiB of float frames.
        if (!a->gif.empty() &&
            double(a->frames) * settings.camera.width * settings.camera.height > double(1 << 28))
            throw Error("--gif with " + std::to_string(a->frames) + " frames of " + a->render.size +
                        " would not fit in memory; use fewer frames or a smaller --size");
        const Volume volume = loadVolumeFromArgs(a->volume);
        std::error_code ec;
        std::filesystem::create_directories(a->outDir, ec);
        if (!std::filesystem::is_directory(a->outDir))
            throw Error(a->outDir + ": cannot create output folder");
        const Renderer renderer(volume, settings);
        std::vector<Image> frames;
        double totalMs = 0;
        WriteOptions display;
        for (int f = 0; f < a->frames; ++f) {
            CameraParams cam = settings.camera;
            cam.azimuthDeg = a->from + (a->to - a->from) * f / a->frames;
            RenderStats stats;
            Image image = renderer.render(cam, &stats);
            totalMs += stats.milliseconds;
            if (f == 0) display = displayOptions(a->render, settings, image);
            writeImage(frameName(a->outDir, f, a->format), image, display);
            std::fprintf(stderr, "\rframe %d/%d (azimuth %.1f, %.0f ms)   ", f + 1, a->frames,
                         cam.azimuthDeg, stats.milliseconds);
            if (!a->gif.empty()) frames.push_back(std::move(image));
        }
        std::fprintf(stderr, "\n");
        if (!a->gif.empty()) writeAnimatedGif(a->gif, frames, display, a->fps);
        std::printf("wrote %d frames to %s%s%s (%.1f ms per frame)\n", a->frames, a->outDir.c_str(),
                    a->gif.empty() ? "" : " and ", a->gif.c_str(), totalMs / a->frames);
    });
}

}  // namespace splat::cli
