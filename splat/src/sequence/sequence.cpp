// The sequence engine (see splat/sequence.h).
#include "splat/sequence.h"

#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "splat/error.h"
#include "splat/frame_farm.h"

namespace splat {

// frame_farm.cpp: the views rendered by an installed FrameFarm (splat/frame_farm.h).
void renderSequenceOnFarm(FrameFarm& farm, const Scene& scene,
                          const std::vector<RendererKind>& renderers, const CameraPath& path,
                          const std::vector<std::size_t>& views, const SequenceOptions& options,
                          const std::function<void(SequenceFrame&&)>& sink);

namespace {
constexpr int kMaxFrames = 100000;

double number(const nlohmann::json& key, const char* name, double fallback, const std::string& file,
              std::size_t index) {
    if (!key.contains(name)) return fallback;
    const nlohmann::json& v = key.at(name);
    if (!v.is_number() || !std::isfinite(v.get<double>()))
        throw Error(file + ": keys[" + std::to_string(index) + "]." + name +
                    " must be a finite number");
    return v.get<double>();
}
}  // namespace

CameraPath CameraPath::turn(const CameraParams& base, Angle angle, double from, double to,
                            int frames) {
    if (frames < 1 || frames > kMaxFrames)
        throw Error("a sequence needs 1 to " + std::to_string(kMaxFrames) + " frames");
    if (!std::isfinite(from) || !std::isfinite(to)) throw Error("--from/--to must be finite");
    if (base.lookAtSet)
        throw Error(
            "a turn orbits the volume centre by azimuth or elevation; a free camera "
            "(--eye/--look-at) does not turn: give its views as a camera path");
    CameraPath p;
    for (int f = 0; f < frames; ++f) {
        const double t = frames > 1 ? double(f) / (frames - 1) : 0.0;
        CameraParams c = base;
        (angle == Angle::Azimuth ? c.azimuthDeg : c.elevationDeg) = from + (to - from) * t;
        p.views.push_back(c);
    }
    return p;
}

CameraPath CameraPath::fromJson(const std::string& path, const CameraParams& base, int frames) {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot read the camera path");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const std::exception&) {
        throw Error(path + ": not valid JSON");
    }
    if (!j.is_object() || !j.contains("keys") || !j.at("keys").is_array())
        throw Error(path + ": a camera path is {\"keys\": [{\"azimuth\": ..., ...}, ...]}");
    for (const auto& [name, value] : j.items())
        if (name != "keys") throw Error(path + ": unknown key '" + name + "'");
    const nlohmann::json& keys = j.at("keys");
    if (keys.size() < 2) throw Error(path + ": a camera path needs at least 2 keys");
    if (frames < 2 || frames > kMaxFrames)
        throw Error("a camera path needs 2 to " + std::to_string(kMaxFrames) + " frames");
    std::vector<CameraParams> k;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        const nlohmann::json& key = keys[i];
        if (!key.is_object())
            throw Error(path + ": keys[" + std::to_string(i) + "] is not an object");
        for (const auto& [name, value] : key.items())
            if (name != "azimuth" && name != "elevation" && name != "distance" &&
                name != "pixel_size")
                throw Error(path + ": keys[" + std::to_string(i) + "]: unknown key '" + name +
                            "' (azimuth, elevation, distance, pixel_size)");
        CameraParams c = base;
        c.azimuthDeg = number(key, "azimuth", base.azimuthDeg, path, i);
        c.elevationDeg = number(key, "elevation", base.elevationDeg, path, i);
        c.distance = number(key, "distance", base.distance, path, i);
        c.pixelSize = number(key, "pixel_size", base.pixelSize, path, i);
        k.push_back(c);
    }
    CameraPath p;
    for (int f = 0; f < frames; ++f) {
        const double u = double(f) * double(k.size() - 1) / double(frames - 1);
        const std::size_t a = std::min(k.size() - 2, std::size_t(u));
        const double t = u - double(a);
        auto lerp = [&](double x, double y) { return x + (y - x) * t; };
        CameraParams c = k[a];
        c.azimuthDeg = lerp(k[a].azimuthDeg, k[a + 1].azimuthDeg);
        c.elevationDeg = lerp(k[a].elevationDeg, k[a + 1].elevationDeg);
        c.distance = lerp(k[a].distance, k[a + 1].distance);
        c.pixelSize = lerp(k[a].pixelSize, k[a + 1].pixelSize);
        p.views.push_back(c);
    }
    return p;
}

void renderSequence(const Scene& scene, const std::vector<RendererKind>& renderers,
                    const CameraPath& path, const SequenceOptions& options,
                    const std::function<void(SequenceFrame&&)>& sink) {
    if (renderers.empty()) throw Error("sequence: no renderer");
    std::vector<std::size_t> views;
    for (std::size_t v = 0; v < path.views.size(); ++v)
        if (!options.skip || !options.skip(v)) views.push_back(v);
    if (FrameFarm* farm = installedFrameFarm())
        return renderSequenceOnFarm(*farm, scene, renderers, path, views, options, sink);
    const std::size_t total = views.size() * renderers.size();
    std::size_t done = 0;
    std::mutex progressMutex;
    std::atomic<bool> cancelled{false};

    auto renderView = [&](std::size_t v, int threads) {
        SequenceFrame f;
        f.view = v;
        f.images.resize(renderers.size());
        f.stats.resize(renderers.size());
        RenderSettings s = scene.settings();
        s.camera = path.views[v];
        if (threads > 0) s.threads = threads;
        for (std::size_t k = 0; k < renderers.size() && !cancelled; ++k) {
            s.renderer = renderers[k];
            const std::string name =
                std::string(toString(renderers[k])) + ", view " + std::to_string(v + 1);
            // Inside the frame: progress polled per tile or row (same done and total), so a
            // cancel stops the frame in flight, not only the next one.
            s.progress = [&](std::size_t tick, std::size_t ticks, const std::string& unit) {
                std::lock_guard<std::mutex> lock(progressMutex);
                if (!cancelled && options.progress &&
                    !options.progress(done, total,
                                      name + ": " + unit + " " + std::to_string(tick) + "/" +
                                          std::to_string(ticks)))
                    cancelled = true;
                return !cancelled;
            };
            f.images[k] = scene.render(s, &f.stats[k]);
            std::lock_guard<std::mutex> lock(progressMutex);
            ++done;
            if (options.progress && !options.progress(done, total,
                                                      std::string(toString(renderers[k])) +
                                                          ", view " + std::to_string(v + 1)))
                cancelled = true;
        }
        return f;
    };

    std::size_t batch = 1;
    if (options.parallelFrames > 0) {
        batch = std::size_t(options.parallelFrames);
    } else if (!path.views.empty()) {
        const CameraParams& c = path.views.front();
        const int threads = scene.settings().threads > 0 ? scene.settings().threads
                                                         : tbb::info::default_concurrency();
        if (std::int64_t(c.width) * c.height <= 256 * 256)
            batch = std::size_t(std::max(threads, 1));
    }
    for (std::size_t n0 = 0; n0 < views.size(); n0 += batch) {
        const std::size_t n1 = std::min(views.size(), n0 + batch);
        std::vector<SequenceFrame> frames(n1 - n0);
        if (batch == 1)
            frames[0] = renderView(views[n0], 0);
        else
            tbb::parallel_for(n0, n1,
                              [&](std::size_t n) { frames[n - n0] = renderView(views[n], 1); });
        if (cancelled) throw Cancelled();
        for (SequenceFrame& f : frames) sink(std::move(f));
    }
}

}  // namespace splat
