// The splat side of the side-by-side benchmark (tools/bench/vs_vtk.py): everything the
// script needs from the library, in three subcommands.
//
//   bench_frames export VOLUME OUT.mha
//       writes the volume as a float MetaImage with splat's world grid (origin, spacing),
//       so that another renderer sees the same samples at the same world positions.
//   bench_frames render VOLUME TF [RENDER OPTIONS] [--frames F] [--warmup 0|1]
//       [--save 0,4,..] [--out DIR]
//       renders a rotation of F frames (azimuth 360 k / F, default 12) and prints JSON: per
//       frame its wall and CPU time, stage counters, level of detail used, pixel-filter passes
//       (the filtered reference) and the camera (target, right, up, view, pixel size), and the
//       scene's build time, splat count and bytes per splat. RENDER OPTIONS are `splat
//       render`'s own, from the library's option table (splat/options.h: --renderer, --mode, --slab, --lod, --ewa,
//       --pixel-filter, --size WxH or N, --threads (default 2), --elevation (default 15), ...),
//       and --factorised-sheets N (Quality::factorisedSheets, not a `splat render` option yet),
//       read by the same code, so any value the command line accepts (e.g. a new `--lod`
//       mode) works here too; TF is the --tf value (a preset or a JSON file). Frames listed in
//       --save are written to DIR/frame_K.f32 (float RGBA, row 0 at the top); the reference
//       renders only those.
//   bench_frames compare A B W H
//       RMSE and max abs difference of the RGB of two W x H images over black, each a .f32
//       (float RGBA premultiplied, top row first) or .rgb8 (8-bit RGB, bottom row first, as
//       OpenGL reads a frame buffer): prints {"rmse": .., "max": ..}.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "splat/options.h"
#include "splat/error.h"
#include "splat/scene.h"
#include "splat/volume_io.h"

namespace {

using Clock = std::chrono::steady_clock;

/// CPU time of the whole process (all threads), ms: the work a frame did, which a loaded
/// machine stretches far less than its wall time.
double cpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double msSince(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

std::string vec(const glm::dvec3& v) {
    std::ostringstream o;
    o.precision(17);
    o << '[' << v.x << ", " << v.y << ", " << v.z << ']';
    return o.str();
}

int exportVolume(const std::string& spec, const std::string& out) {
    const splat::Volume v = splat::loadVolume(spec);
    splat::saveMetaImage(out, v);
    const splat::VolumeStats st = splat::volumeStats(v, 1);
    std::cout << "{\"dims\": [" << v.dims.x << ", " << v.dims.y << ", " << v.dims.z
              << "], \"spacing\": " << vec(v.spacing) << ", \"origin\": " << vec(v.origin)
              << ", \"min\": " << st.minValue << ", \"max\": " << st.maxValue
              << ", \"float_bytes\": " << v.bytes() << "}\n";
    return 0;
}

void writeFloats(const std::string& path, const splat::Image& image) {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(image.pixels.data()),
            std::streamsize(image.pixels.size() * sizeof(glm::vec4)));
    if (!f) throw splat::Error(path + ": cannot write");
}

int renderRotation(const std::string& spec, const std::string& tf,
                   std::vector<std::string> args) {
    CLI::App app{"bench_frames render"};
    splat::OptionValues values(splat::kRenderOptions);
    values.textSlot("tf") = tf;
    values.textSlot("threads") = "2";
    values.textSlot("elevation") = "15";
    for (const splat::OptionSpec* o : values.specs()) {
        const std::string flag = "--" + std::string(o->name), help(o->help);
        if (o->type == splat::OptionType::Flag)
            app.add_flag(flag, values.flagSlot(o->name), help);
        else if (o->type == splat::OptionType::TextList)
            app.add_option(flag, values.listSlot(o->name), help);
        else
            app.add_option(flag, values.textSlot(o->name), help);
    }
    int frames = 12, warmupFlag = 1;
    std::string saveList, out = ".";
    app.add_option("--frames", frames, "frames of the rotation");
    app.add_option("--warmup", warmupFlag, "1: render two frames before timing");
    app.add_option("--save", saveList, "frames to write as DIR/frame_K.f32");
    app.add_option("--out", out, "folder of the saved frames");
    int factorised = 0;
    app.add_option("--factorised-sheets", factorised,
                   "axis-aligned: factorised sheets with N samples per voxel (0: off)");
    // --size N means N x N.
    for (std::size_t i = 0; i + 1 < args.size(); ++i)
        if (args[i] == "--size" && args[i + 1].find_first_of("xX") == std::string::npos)
            args[i + 1] += "x" + args[i + 1];
    std::vector<const char*> argv = {"bench_frames render"};
    for (const std::string& arg : args) argv.push_back(arg.c_str());
    try {
        app.parse(int(argv.size()), argv.data());
    } catch (const CLI::ParseError& e) {
        std::cerr << "bench_frames: error: " << e.what() << '\n';
        return 2;
    }
    for (const splat::OptionSpec* o : values.specs())
        if (app.get_option("--" + std::string(o->name))->count() > 0)
            values.markGiven(o->name, false);
    splat::RenderSettings s = splat::renderSettingsFrom(
        values, splat::RenderUse{},
        [](const std::string& line) { std::cerr << "bench_frames: warning: " << line << '\n'; });
    // Given, it wins over the frame design a --quality preset chose.
    if (app.get_option("--factorised-sheets")->count() > 0)
        s.quality.factorisedSheets = factorised;
    frames = std::max(1, frames);
    const double elevation = s.camera.elevationDeg;
    const bool warmup = warmupFlag != 0;
    const int size = s.camera.width;
    std::vector<int> save;
    {
        std::stringstream list(saveList);
        for (std::string item; std::getline(list, item, ',');)
            if (!item.empty()) save.push_back(std::stoi(item));
    }

    auto volume = std::make_shared<const splat::Volume>(splat::loadVolume(spec));
    const auto built = Clock::now();
    s = splat::withFreeCameraTarget(s, *volume);
    const splat::Scene scene(volume, s);
    const double sceneMs = msSince(built);
    const bool onlySaved = s.renderer == splat::RendererKind::Reference;
    auto cameraOf = [&](int f) {
        splat::RenderSettings frame = s;
        frame.camera.azimuthDeg = 360.0 * f / frames;
        frame.camera.elevationDeg = elevation;
        return frame;
    };
    auto wanted = [&](int f) {
        return !onlySaved || std::find(save.begin(), save.end(), f) != save.end();
    };
    // Warm-up: the first frames build the scene's lazy orders and the frame workspaces (a
    // quarter turn apart, so both horizontal sheet axes are seen).
    if (warmup && !onlySaved)
        for (int f : {0, frames / 4}) scene.render(cameraOf(f));

    std::ostringstream json;
    json.precision(10);
    const splat::SplatList& sp = scene.splats();
    json << "{\"renderer\": \"" << splat::toString(s.renderer) << "\", \"size\": " << size
         << ", \"threads\": " << s.threads << ", \"slab\": " << s.quality.slab
         << ", \"mode\": \"" << splat::toString(s.mode)
         << "\", \"lod\": " << s.quality.lod.pixels
         << ", \"ewa\": \"" << splat::toString(s.quality.ewa)
         << "\", \"pixel_filter\": " << s.quality.pixelFilter << ", \"scene_ms\": " << sceneMs
         << ", \"splats\": " << sp.size() << ", \"splat_bytes\": " << sp.bytes()
         << ", \"voxels\": " << volume->voxelCount() << ", \"spacing\": " << vec(volume->spacing)
         << ", \"frames\": [";
    bool first = true;
    for (int f = 0; f < frames; ++f) {
        if (!wanted(f)) continue;
        const splat::RenderSettings frame = cameraOf(f);
        splat::RenderStats st;
        const auto t = Clock::now();
        const double c = cpuMs();
        const splat::Image image = scene.render(frame, &st);
        const double ms = msSince(t), cpu = cpuMs() - c;
        if (std::find(save.begin(), save.end(), f) != save.end())
            writeFloats(out + "/frame_" + std::to_string(f) + ".f32", image);
        const splat::Camera cam(frame.camera, *volume);
        json << (first ? "" : ", ") << "\n  {\"frame\": " << f
             << ", \"azimuth\": " << frame.camera.azimuthDeg << ", \"elevation\": " << elevation
             << ", \"ms\": " << ms << ", \"cpu_ms\": " << cpu
             << ", \"project_ms\": " << st.projectMs << ", \"order_ms\": " << st.orderMs
             << ", \"bin_ms\": " << st.binMs << ", \"tiles_ms\": " << st.tilesMs
             << ", \"footprint_pixels\": " << st.footprintPixels
             << ", \"culled_splats\": " << st.culledSplats
             << ", \"warp_fix_pixels\": " << st.warpFixPixels
             << ", \"warp_fix_tiles\": " << st.warpFixTiles << ", \"sheets\": " << st.sheets
             << ", \"lod_level\": " << st.lodLevel << ", \"lod_splats\": " << st.lodSplats
             << ", \"pixel_samples\": " << st.pixelSamples
             << ", \"pixel_filter_change\": " << st.pixelFilterChange
             << ", \"target\": " << vec(cam.target) << ", \"right\": " << vec(cam.right)
             << ", \"up\": " << vec(cam.up) << ", \"view\": " << vec(cam.view)
             << ", \"pixel_size\": " << cam.pixelSize << ", \"radius\": " << cam.boundingRadius
             << "}";
        first = false;
    }
    json << "]}\n";
    std::cout << json.str();
    return 0;
}

/// RGB over black of pixel n of a .f32 (top-down RGBA float) or .rgb8 (bottom-up RGB bytes).
std::vector<float> readRgb(const std::string& path, int w, int h) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw splat::Error(path + ": cannot open");
    const std::size_t n = std::size_t(w) * std::size_t(h);
    std::vector<float> rgb(3 * n);
    const bool bytes = path.size() > 5 && path.substr(path.size() - 5) == ".rgb8";
    if (bytes) {
        std::vector<unsigned char> raw(3 * n);
        f.read(reinterpret_cast<char*>(raw.data()), std::streamsize(raw.size()));
        if (!f)
            throw splat::Error(path + ": shorter than " + std::to_string(w) + "x" +
                               std::to_string(h) + " RGB bytes");
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 3; ++c)
                    rgb[3 * (std::size_t(y) * w + x) + c] =
                        raw[3 * (std::size_t(h - 1 - y) * w + x) + c] / 255.0f;
    } else {
        std::vector<float> raw(4 * n);
        f.read(reinterpret_cast<char*>(raw.data()), std::streamsize(raw.size() * sizeof(float)));
        if (!f)
            throw splat::Error(path + ": shorter than " + std::to_string(w) + "x" +
                               std::to_string(h) + " RGBA floats");
        for (std::size_t p = 0; p < n; ++p)
            for (int c = 0; c < 3; ++c) rgb[3 * p + c] = raw[4 * p + c];
    }
    return rgb;
}

int compare(const std::string& a, const std::string& b, int w, int h) {
    const std::vector<float> x = readRgb(a, w, h), y = readRgb(b, w, h);
    double sum = 0, mx = 0;
    for (std::size_t n = 0; n < x.size(); ++n) {
        const double d = double(x[n]) - double(y[n]);
        sum += d * d;
        mx = std::max(mx, std::abs(d));
    }
    std::printf("{\"rmse\": %.6g, \"max\": %.6g}\n", std::sqrt(sum / double(x.size())), mx);
    return 0;
}

int usage() {
    std::cerr << "usage: bench_frames export VOLUME OUT.mha\n"
                 "       bench_frames render VOLUME TF [splat render's options] [--frames F] "
                 "[--warmup 0|1] [--save LIST] [--out DIR]\n"
                 "       bench_frames compare A B W H\n";
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::string> a(argv + 1, argv + argc);
    try {
        if (a.size() == 3 && a[0] == "export") return exportVolume(a[1], a[2]);
        if (a.size() >= 3 && a[0] == "render")
            return renderRotation(a[1], a[2], {a.begin() + 3, a.end()});
        if (a.size() == 5 && a[0] == "compare")
            return compare(a[1], a[2], std::stoi(a[3]), std::stoi(a[4]));
        return usage();
    } catch (const std::exception& e) {
        std::cerr << "bench_frames: error: " << e.what() << '\n';
        return 1;
    }
}
