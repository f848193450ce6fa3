// bench_footprint: the speed/accuracy trade-off of the footprint and slab tables.
//
//   bench_footprint [--json FILE] [--kernel gaussian|bspline]
//
// For each table resolution prints the build time, the memory, the maximum error relative
// to the footprint's peak (Gaussian: vs the closed form with erf; B-spline: vs adaptive
// quadrature) and the lookup throughput on a random r^2 stream (one thread; a checksum
// is printed so the loop cannot be optimised away).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "footprint/closed_form.h"
#include "footprint/footprint_table.h"
#include "footprint/kernel.h"
#include "footprint/slab_table.h"

using footprint::FootprintTable;
using footprint::Kernel;
using footprint::SlabTable;

namespace {

constexpr double kPi = 3.14159265358979323846;
using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
}

bool isGaussian(const Kernel& k) { return k.type() == footprint::KernelType::Gaussian; }


double checksum(const std::vector<float>& v) {
    double s = 0;
    for (float x : v) s += x;
    return s;
}

struct FpRow {
    int resolution;
    double buildMs, maxErr, mlps;
    std::size_t bytes;
    double checksum;
};

struct SlabRow {
    int nr, nz;
    double buildMs, maxErr, sumErr, msps;
    std::size_t bytes;
    double checksum;
};

}  // namespace

int main(int argc, char** argv) {
    std::string json, kernelName = "gaussian";
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--json") && i + 1 < argc) {
            json = argv[++i];
        } else if (!std::strcmp(argv[i], "--kernel") && i + 1 < argc) {
            kernelName = argv[++i];
        } else {
            std::fprintf(stderr, "usage: %s [--json FILE] [--kernel gaussian|bspline]\n", argv[0]);
            return 2;
        }
    }
    Kernel kernel = Kernel::defaultKernel();
    try {
        kernel = Kernel::fromName(kernelName);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_footprint: %s\n", e.what());
        return 2;
    }
    const double R = kernel.radius();
    const bool closed = isGaussian(kernel);
    const FootprintTable reference(kernel, 16);  // for exact() quadrature

    // Random query streams (10% beyond R, as in a splat's bounding box).
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> U(0, 1);
    // 16 Ki queries (64 KiB per array): an in-cache stream like a tile's sheet buffer, so
    // the numbers measure the table lookups rather than memory bandwidth.
    const int n = 1 << 14;
    std::vector<float> r2s(n), z0s(n), z1s(n);
    for (int i = 0; i < n; ++i) {
        r2s[i] = float(R * R) * 1.1f * U(rng);
        float a = float(R) * (2.2f * U(rng) - 1.1f), b = float(R) * (2.2f * U(rng) - 1.1f);
        z0s[i] = std::min(a, b);
        z1s[i] = std::max(a, b);
    }
    const int reps = 2560;
    std::vector<float> out(n);

    std::printf("bench_footprint  kernel %s  (errors relative to the footprint peak, vs %s)\n\n",
                kernel.name().c_str(), closed ? "the closed form" : "adaptive quadrature");
    std::printf("Footprint table fp(r), linear in r^2 (default %d)\n",
                FootprintTable::kDefaultResolution);
    std::printf("%10s %10s %12s %13s %14s %14s\n", "entries", "build ms", "bytes", "max error",
                "Mlookups/s", "checksum");
    std::vector<FpRow> fpRows;
    for (int res = 256; res <= 65536; res *= 2) {
        auto t0 = Clock::now();
        const FootprintTable t(kernel, res);
        auto t1 = Clock::now();
        double err = 0;
        const int samples = 200000;
        for (int i = 0; i <= samples; ++i) {
            const double r2 = R * R * i / samples;
            const double ex =
                closed ? footprint::gaussianFootprintClosedForm(kernel, std::sqrt(r2)) : reference.exact(std::sqrt(r2));
            err = std::max(err, std::abs(t.lookup(float(r2)) - ex));
            if (!closed) i += 19;  // quadrature is slower
        }
        err /= t.peak();
        std::fill(out.begin(), out.end(), 0.0f);
        auto t2 = Clock::now();
        for (int rep = 0; rep < reps; ++rep)
            for (int i = 0; i < n; ++i) out[i] += t.lookup(r2s[i]);  // like a sheet buffer
        auto t3 = Clock::now();
        const double sum = checksum(out);
        FpRow row{res,       1e3 * seconds(t0, t1),
                  err,       double(n) * reps / seconds(t2, t3) / 1e6,
                  t.bytes(), sum};
        fpRows.push_back(row);
        std::printf("%10d %10.2f %12zu %13.2e %14.0f %14.6g%s\n", res, row.buildMs, row.bytes,
                    row.maxErr, row.mlps, row.checksum,
                    res == FootprintTable::kDefaultResolution ? "  <- default" : "");
    }

    std::printf("\nSlab table C(r, z) = fp(r^2) * F(r^2, z), F bilinear (default %d x %d)\n",
                SlabTable::kDefaultRadial, SlabTable::kDefaultDepth);
    std::printf("%6s x %-6s %10s %12s %13s %13s %14s %14s\n", "r^2", "z", "build ms", "bytes",
                "section err", "partition err", "Msections/s", "checksum");
    std::vector<SlabRow> slabRows;
    const int cfg[][2] = {{32, 256}, {64, 512}, {64, 1024}, {128, 1024}, {256, 2048}, {512, 4096}};
    for (const auto& c : cfg) {
        auto t0 = Clock::now();
        const SlabTable s(kernel, c[0], c[1]);
        auto t1 = Clock::now();
        const double peak = s.footprint().peak();
        std::mt19937 g(7);
        std::uniform_real_distribution<double> V(0, 1);
        double err = 0, sumErr = 0;
        for (int i = 0; i < (closed ? 20000 : 2000); ++i) {
            const double r2 = R * R * V(g) * V(g), r = std::sqrt(r2);
            double a = R * (2.2 * V(g) - 1.1),
                   b = (i % 4 == 0) ? a + 0.2 * V(g) : R * (2.2 * V(g) - 1.1);
            if (a > b) std::swap(a, b);
            const double ex = closed
                                  ? footprint::gaussianCumulativeClosedForm(kernel, r, b) - footprint::gaussianCumulativeClosedForm(kernel, r, a)
                                  : s.exact(r, b) - s.exact(r, a);
            err = std::max(err, std::abs(s.section(float(r2), float(a), float(b)) - ex));
            // A partition of [-R, R] into 16 random slabs sums to the footprint.
            if (i % 10 == 0) {
                std::vector<float> cuts{float(-R), float(R)};
                for (int k = 0; k < 15; ++k) cuts.push_back(float(R * (2 * V(g) - 1)));
                std::sort(cuts.begin(), cuts.end());
                double sum = 0;
                for (std::size_t k = 0; k + 1 < cuts.size(); ++k)
                    sum += s.section(float(r2), cuts[k], cuts[k + 1]);
                sumErr = std::max(sumErr, std::abs(sum - s.footprint().lookup(float(r2))));
            }
        }
        std::fill(out.begin(), out.end(), 0.0f);
        auto t2 = Clock::now();
        for (int rep = 0; rep < reps / 2; ++rep)
            for (int i = 0; i < n; ++i) out[i] += s.section(r2s[i], z0s[i], z1s[i]);
        auto t3 = Clock::now();
        const double sum = checksum(out);
        SlabRow row{c[0],
                    c[1],
                    1e3 * seconds(t0, t1),
                    err / peak,
                    sumErr / peak,
                    double(n) * (reps / 2) / seconds(t2, t3) / 1e6,
                    s.bytes(),
                    sum};
        slabRows.push_back(row);
        const bool def = c[0] == SlabTable::kDefaultRadial && c[1] == SlabTable::kDefaultDepth;
        std::printf("%6d x %-6d %10.2f %12zu %13.2e %13.2e %14.0f %14.6g%s\n", row.nr, row.nz,
                    row.buildMs, row.bytes, row.maxErr, row.sumErr, row.msps, row.checksum,
                    def ? "  <- default" : "");
    }
    std::printf(
        "\nmax error: over %s; section err: 20000 random sections (a quarter of them thinner "
        "than 0.2 voxel);\npartition err: 16 random slabs vs the full footprint. One thread, "
        "%d-entry random stream,\nrepeated (10%% of it beyond R), "
        "results added into an output array.\n",
        "200001 r^2 values uniform in [0, R^2]", n);

    if (!json.empty()) {
        std::ostringstream o;
        o.precision(10);
        o << "{\n  \"kernel\": \"" << kernel.name() << "\",\n  \"footprint\": [\n";
        for (std::size_t i = 0; i < fpRows.size(); ++i) {
            const auto& r = fpRows[i];
            o << "    {\"resolution\": " << r.resolution << ", \"build_ms\": " << r.buildMs
              << ", \"bytes\": " << r.bytes << ", \"max_error_rel_peak\": " << r.maxErr
              << ", \"mlookups_per_s\": " << r.mlps << ", \"checksum\": " << r.checksum << "}"
              << (i + 1 < fpRows.size() ? "," : "") << "\n";
        }
        o << "  ],\n  \"slab\": [\n";
        for (std::size_t i = 0; i < slabRows.size(); ++i) {
            const auto& r = slabRows[i];
            o << "    {\"radial\": " << r.nr << ", \"depth\": " << r.nz
              << ", \"build_ms\": " << r.buildMs << ", \"bytes\": " << r.bytes
              << ", \"max_section_error_rel_peak\": " << r.maxErr
              << ", \"max_partition_error_rel_peak\": " << r.sumErr
              << ", \"msections_per_s\": " << r.msps << ", \"checksum\": " << r.checksum << "}"
              << (i + 1 < slabRows.size() ? "," : "") << "\n";
        }
        o << "  ]\n}\n";
        const std::string tmp = json + ".tmp";
        {
            std::ofstream f(tmp);
            f << o.str();
            if (!f) {
                std::fprintf(stderr, "bench_footprint: cannot write %s\n", json.c_str());
                return 1;
            }
        }
        if (std::rename(tmp.c_str(), json.c_str()) != 0) {
            std::fprintf(stderr, "bench_footprint: cannot write %s\n", json.c_str());
            return 1;
        }
    }
    return 0;
}
