// Float against double accumulation (docs/speed-vs-accuracy.md "Float and double").
//
// The splatters accumulate footprints and composite sheets in float. This program measures
// what that costs on a large frame: the X-ray of synthetic:phantom:N (N = 512 by default)
// at S×S pixels (2048² by default), seen along the volume's y axis (azimuth 0, elevation 0,
// orthographic), where the exact image is a closed form,
//
//     I(pixel) = Σ_i d_i fp(r_i) / |S⁻¹ω|        (docs/design.md "Footprints"; |S⁻¹ω| = 1 here),
//
// summed here in double over every voxel whose kernel the pixel's ray crosses (the voxel
// columns within the kernel radius of the ray). Two sums are formed per sampled pixel: with
// the same float footprint table the splatters read (the difference to the splatter is
// then float accumulation plus the splatter's own footprint evaluation path), and with the
// footprint by quadrature in double (the table's error added). Printed: the largest and the
// RMS difference over the sampled pixels, relative to the image's peak, and the depth of
// the sums (kernels per ray).
//
// Usage: bench_precision [N] [SIZE] [SAMPLES_PER_SIDE] [axis|sheet]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "footprint/footprint_table.h"
#include "footprint/kernel.h"
#include "splat/camera.h"
#include "splat/render.h"
#include "splat/synthetic.h"

int main(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 512;
    const int size = argc > 2 ? std::atoi(argv[2]) : 2048;
    const int samples = argc > 3 ? std::atoi(argv[3]) : 48;
    const std::string renderer = argc > 4 ? argv[4] : "axis";
    if (n < 8 || size < 16 || samples < 2 || samples > size) {
        std::fprintf(stderr,
                     "usage: bench_precision [N>=8] [SIZE>=16] [SAMPLES 2..SIZE] [axis|sheet]\n");
        return 2;
    }
    using namespace splat;
    const Volume volume = makeSynthetic("phantom", n);
    RenderSettings s;
    s.renderer = parseRenderer(renderer);
    s.mode = RenderMode::Xray;
    s.camera.width = s.camera.height = size;
    s.camera.azimuthDeg = 0;
    s.camera.elevationDeg = 0;
    const auto t0 = std::chrono::steady_clock::now();
    RenderStats stats;
    const Image img = render(volume, s, &stats);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

    const footprint::Kernel kernel = footprint::Kernel::fromName(s.kernel, 0, 0);
    const footprint::FootprintTable fp(kernel);
    const double R = fp.radius();
    const Camera cam(s.camera, volume);
    float peak = 0;
    for (const auto& p : img.pixels) peak = std::max(peak, p[0]);

    // Pixel ray in index space: p(t) = a + t·(0, 1, 0) (spacing 1, view along +y).
    double worstTable = 0, worstExact = 0, sumSqTable = 0, sumSqExact = 0;
    std::size_t counted = 0, maxDepth = 0;
    for (int sy = 0; sy < samples; ++sy)
        for (int sx = 0; sx < samples; ++sx) {
            const int x = int((sx + 0.5) * size / samples), y = int((sy + 0.5) * size / samples);
            const Ray ray = cam.ray(x + 0.5, y + 0.5);
            const glm::dvec3 a = (ray.origin - volume.origin) / volume.spacing;
            double sumTable = 0, sumExact = 0;
            std::size_t depth = 0;
            const int i0 = std::max(0, int(std::ceil(a.x - R))),
                      i1 = std::min(n - 1, int(std::floor(a.x + R)));
            const int k0 = std::max(0, int(std::ceil(a.z - R))),
                      k1 = std::min(n - 1, int(std::floor(a.z + R)));
            for (int k = k0; k <= k1; ++k)
                for (int i = i0; i <= i1; ++i) {
                    const double r2 = (i - a.x) * (i - a.x) + (k - a.z) * (k - a.z);
                    if (r2 >= R * R) continue;
                    const double wTable = fp.lookup(float(r2));
                    const double wExact = fp.exact(std::sqrt(r2));
                    for (int j = 0; j < n; ++j) {
                        const float d = volume.at(i, j, k);
                        if (d == 0.0f) continue;
                        sumTable += double(d) * wTable;
                        sumExact += double(d) * wExact;
                        ++depth;
                    }
                }
            const double got = img.pixels[std::size_t(y) * size + x][0];
            worstTable = std::max(worstTable, std::abs(got - sumTable));
            worstExact = std::max(worstExact, std::abs(got - sumExact));
            sumSqTable += (got - sumTable) * (got - sumTable);
            sumSqExact += (got - sumExact) * (got - sumExact);
            maxDepth = std::max(maxDepth, depth);
            ++counted;
        }
    std::printf(
        "phantom:%d  %dx%d  %s xray  %.0f ms  peak %.6g  sampled pixels %zu  kernels per ray "
        "up to %zu\n",
        n, size, size, renderer.c_str(), ms, double(peak), counted, maxDepth);
    std::printf("float image vs double sum, same float table: max %.3g, RMS %.3g of the peak\n",
                worstTable / peak, std::sqrt(sumSqTable / double(counted)) / peak);
    std::printf(
        "float image vs double sum, footprint by quadrature: max %.3g, RMS %.3g of the peak\n",
        worstExact / peak, std::sqrt(sumSqExact / double(counted)) / peak);
    return 0;
}
