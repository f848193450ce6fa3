// Frame time of the Gaussian renderers (splat/gaussians.h) on a generated scene:
// `gaussians:random:N` (N Gaussians in the unit cube, SH degree 3), orbit camera, median of
// the rounds per renderer. Never a test: run it niced on an idle machine.
//
//   bench_gaussians [--count N] [--size WxH] [--threads T] [--rounds R]
//                   [--renderers 3dgs,3dgs-pixel,sheet,reference] [--slab H] [--tolerance E]
// prints {"count": N, "width": W, "height": H, "threads": T, "runs": [{"renderer": ..,
// "ms": [..], "median_ms": ..}, ...]}.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "splat/error.h"
#include "splat/gaussians.h"

int main(int argc, char** argv) {
    using namespace splat;
    std::size_t count = 1000000;
    int width = 1280, height = 720, threads = 2, rounds = 3;
    double slab = 0, tolerance = 1e-4;
    std::string renderers = "3dgs";
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string k = argv[i], v = argv[i + 1];
        if (k == "--count")
            count = std::stoul(v);
        else if (k == "--size")
            std::sscanf(v.c_str(), "%dx%d", &width, &height);
        else if (k == "--threads")
            threads = std::stoi(v);
        else if (k == "--rounds")
            rounds = std::max(1, std::stoi(v));
        else if (k == "--renderers")
            renderers = v;
        else if (k == "--slab")
            slab = std::stod(v);
        else if (k == "--tolerance")
            tolerance = std::stod(v);
        else {
            std::fprintf(stderr, "bench_gaussians: unknown option %s\n", k.c_str());
            return 2;
        }
    }
    try {
        const auto t0 = std::chrono::steady_clock::now();
        const GaussianScene scene = syntheticGaussians("gaussians:random:" + std::to_string(count));
        const double genMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        CameraParams cam;
        cam.width = width;
        cam.height = height;
        cam.azimuthDeg = 30;
        cam.elevationDeg = 20;
        cam.projection = Projection::Perspective;
        std::printf(
            "{\"count\": %zu, \"width\": %d, \"height\": %d, \"threads\": %d, "
            "\"generate_ms\": %.1f, \"runs\": [",
            count, width, height, threads, genMs);
        std::stringstream list(renderers);
        bool first = true;
        for (std::string name; std::getline(list, name, ',');) {
            GaussianRenderOptions o;
            o.renderer = parseGaussianRenderer(name);
            o.threads = threads;
            o.slab = slab;
            o.tolerance = tolerance;
            std::vector<double> ms;
            for (int r = 0; r < rounds; ++r) {
                const auto a = std::chrono::steady_clock::now();
                const Image img = renderGaussians(scene, cam, o);
                ms.push_back(
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a)
                        .count());
                if (img.pixels.empty()) return 1;
            }
            std::vector<double> sorted = ms;
            std::sort(sorted.begin(), sorted.end());
            std::printf("%s{\"renderer\": \"%s\", \"ms\": [", first ? "" : ", ", name.c_str());
            for (std::size_t k = 0; k < ms.size(); ++k) std::printf("%s%.1f", k ? ", " : "", ms[k]);
            std::printf("], \"median_ms\": %.1f}", sorted[sorted.size() / 2]);
            std::fflush(stdout);
            first = false;
        }
        std::printf("]}\n");
    } catch (const Error& e) {
        std::fprintf(stderr, "bench_gaussians: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
