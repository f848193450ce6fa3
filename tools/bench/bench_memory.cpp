// Memory per sample type and per mode: builds an N^3 Gaussian blob
// stored as TYPE (float32 owned, or borrowed float32/uint8/int16/uint16, the
// caller's buffer allocated here), renders one frame of MODE with RENDERER, and prints the
// peak resident set size. Run it under `/usr/bin/time -v` for the kernel's figure.
//   bench_memory N TYPE MODE RENDERER [SIZE]
//   TYPE: owned | float32 | uint8 | int16 | uint16;  MODE: dvr | mip | xray | iso
//   RENDERER: axis | sheet | reference | none (classification only)
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "splat/render.h"

namespace {

double peakMiB() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;  // KiB on Linux
}

// A Gaussian blob (sigma n / 6) in [0, 1] at voxel q, stored as raw = value / scale.
template <class T>
std::shared_ptr<std::vector<T>> blob(int n, double scale) {
    auto out = std::make_shared<std::vector<T>>(std::size_t(n) * n * n);
    const double c = 0.5 * (n - 1), sigma = n / 6.0;
    std::size_t q = 0;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i, ++q) {
                const double r2 = (i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c);
                const double v = std::exp(-r2 / (2 * sigma * sigma)) / scale;
                (*out)[q] = std::is_floating_point_v<T> ? T(v) : T(std::lround(v));
            }
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 5) {
        std::fprintf(stderr, "usage: bench_memory N TYPE MODE RENDERER [SIZE]\n");
        return 2;
    }
    const int n = std::atoi(argv[1]);
    const std::string type = argv[2], mode = argv[3], renderer = argv[4];
    const int size = argc > 5 ? std::atoi(argv[5]) : 256;
    try {
        splat::RenderSettings s;
        s.camera.width = s.camera.height = size;
        s.camera.azimuthDeg = 30;
        s.camera.elevationDeg = 20;
        s.transfer = splat::TransferFunction::preset("gray-ramp");
        s.mode = mode == "mip"    ? splat::RenderMode::Mip
                 : mode == "xray" ? splat::RenderMode::Xray
                 : mode == "iso"  ? splat::RenderMode::Iso
                                  : splat::RenderMode::Dvr;
        s.renderer = renderer == "axis"    ? splat::RendererKind::Axis
                     : renderer == "sheet" ? splat::RendererKind::Sheet
                                           : splat::RendererKind::Reference;
        // The caller's samples, generated in TYPE (no float copy on the way).
        const glm::ivec3 d(n);
        const glm::dvec3 spacing(1.0), origin(0.0);
        splat::Volume volume;
        if (type == "owned") {
            volume = splat::makeVolume(d, spacing, "blob");
            volume.data = std::move(*blob<float>(n, 1.0));
        } else if (type == "float32") {
            auto b = blob<float>(n, 1.0);
            volume =
                splat::Volume::borrow(b->data(), splat::SampleType::Float32, d, spacing, origin, b);
        } else if (type == "uint8") {
            auto b = blob<std::uint8_t>(n, 1.0 / 255);
            volume = splat::Volume::borrow(b->data(), splat::SampleType::UInt8, d, spacing, origin,
                                           b, 1.0 / 255);
        } else if (type == "int16") {
            auto b = blob<std::int16_t>(n, 1.0 / 30000);
            volume = splat::Volume::borrow(b->data(), splat::SampleType::Int16, d, spacing, origin,
                                           b, 1.0 / 30000);
        } else if (type == "uint16") {
            auto b = blob<std::uint16_t>(n, 1.0 / 60000);
            volume = splat::Volume::borrow(b->data(), splat::SampleType::UInt16, d, spacing, origin,
                                           b, 1.0 / 60000);
        } else {
            std::fprintf(stderr, "unknown type %s\n", type.c_str());
            return 2;
        }
        const double afterVolume = peakMiB();
        const splat::Scene scene(volume, s);
        const double afterScene = peakMiB();
        splat::RenderStats st;
        if (renderer != "none") scene.render(s, &st);
        std::printf(
            "n=%d type=%s mode=%s renderer=%s samples=%.1f MiB splats=%zu "
            "splat_list=%.1f MiB peak: volume %.1f, scene %.1f, frame %.1f MiB\n",
            n, type.c_str(), mode.c_str(), renderer.c_str(), double(volume.bytes()) / 1048576.0,
            scene.splats().size(), double(scene.splats().bytes()) / 1048576.0, afterVolume,
            afterScene, peakMiB());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_memory: %s\n", e.what());
        return 1;
    }
    return 0;
}
