// The reference ray caster's field sample, two ways, on one thread (CPU time per sample):
//
//   bench_ray_sum [RAYS] [SPACING]
//
//  - window: FieldGrid<4>::eval at every sample, the 4^3 lattice points around it (the
//    reference's separable Gaussian path, AVX2 + FMA where the CPU has them);
//  - per ray: the voxels within R of the ray gathered plane by plane along its major axis,
//    each voxel's tapered Gaussian along the ray a 1D Gaussian in t plus the taper's
//    quadratic, h = N exp(-(d^2 + x^2) / 2 sigma^2) - A + B (d^2 + x^2), x = t - t_i,
//    added to the samples it reaches by the recurrence G(x + s) = G(x) r, r <- r exp(-s^2 /
//    sigma^2) (s the spacing): two exponentials per voxel, none per sample.
// RAYS (default 1000) random lines through a 128^3 grid of four random channels, samples
// SPACING voxels apart (default 0.25) over 100 voxels. Prints the largest difference of the
// two (relative to the largest value) and, in three interleaved rounds, ns per sample of
// each and of the per-ray sum's gather alone.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "reference/field.h"

namespace {

using namespace splat;

struct Line {
    glm::dvec3 p0, v;  // p0 + t v, |v| = 1 (voxels), samples at t = k * spacing
};

// A voxel within R of the line: its offset x = t_0 - t_i at its first sample klo.
struct Reach {
    float x0, d2;
    int klo, khi;
    const float* value;
};

struct Taper {
    double r2, s2, n, a, b;  // R^2, 2 sigma^2, N, A, B of footprint/kernel.h
};

double cpuNs() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e9 + double(t.tv_nsec);
}

// The voxels within R of the line's samples 0..n-1, plane by plane along its major axis.
void gatherReach(const FieldGrid<4>& g, const Taper& k, const Line& l, double s, int n,
                 std::vector<Reach>& out) {
    out.clear();
    int m = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(l.v[a]) > std::abs(l.v[m])) m = a;
    const int a1 = (m + 1) % 3, a2 = (m + 2) % 3;
    const double r = std::sqrt(k.r2), e0 = l.p0[m], e1 = l.p0[m] + (n - 1) * s * l.v[m];
    const int first = int(std::ceil(std::min(e0, e1) - r));
    const int last = int(std::floor(std::max(e0, e1) + r));
    const double half = r / std::abs(l.v[m]);  // the cylinder's reach within a plane
    for (int plane = first; plane <= last; ++plane) {
        const glm::dvec3 c = l.p0 + (plane - l.p0[m]) / l.v[m] * l.v;
        for (int i = int(std::ceil(c[a1] - half)); i <= int(std::floor(c[a1] + half)); ++i)
            for (int j = int(std::ceil(c[a2] - half)); j <= int(std::floor(c[a2] + half)); ++j) {
                glm::ivec3 p;
                p[m] = plane;
                p[a1] = i;
                p[a2] = j;
                const glm::dvec3 d = glm::dvec3(p) - l.p0;
                const double ti = glm::dot(d, l.v), d2 = glm::dot(d, d) - ti * ti;
                if (!(d2 < k.r2)) continue;
                const double w = std::sqrt(k.r2 - d2);
                int lo = std::max(0, int(std::ceil((ti - w) / s)));
                int hi = std::min(n - 1, int(std::floor((ti + w) / s)));
                auto inside = [&](int q) { return (q * s - ti) * (q * s - ti) + d2 < k.r2; };
                while (lo <= hi && !inside(lo)) ++lo;
                while (hi >= lo && !inside(hi)) --hi;
                if (lo <= hi)
                    out.push_back({float(lo * s - ti), float(d2), lo, hi,
                                   g.values.data() + g.index(p.x, p.y, p.z)});
            }
    }
}

// Adds one voxel's kernel to its samples; g0 = exp(-(d^2 + x0^2) / s2), r0 = the first ratio,
// step = exp(-2 s^2 / s2) the ratio's own factor per sample.
void addReach(const Reach& v, const Taper& k, float s, float step, float g0, float r0, float* out) {
    const float base = float(k.b * v.d2 - k.a);
    const float b = float(k.b);
    float g = float(k.n) * g0, ratio = r0, x = v.x0;
    float* o = out + std::size_t(v.klo) * 4;
    const __m128 value = _mm_loadu_ps(v.value);
    for (int q = v.klo; q <= v.khi; ++q, o += 4) {
        const float w = g + base + b * x * x;
        _mm_storeu_ps(o, _mm_add_ps(_mm_loadu_ps(o), _mm_mul_ps(_mm_set1_ps(w), value)));
        g *= ratio;
        ratio *= step;
        x += s;
    }
}

#if defined(FOOTPRINT_HAVE_LANES)
FOOTPRINT_LANES_BEGIN
// The two exponentials of eight voxels at a time (expLanes of field.h).
void startLanes(const Reach* v, int count, const Taper& k, float s, float* g0, float* r0) {
    alignas(32) float x[8] = {}, q[8] = {};
    for (int l = 0; l < count; ++l) {
        x[l] = v[l].x0;
        q[l] = v[l].d2 + x[l] * x[l];
    }
    const __m256 minusInvS2 = _mm256_set1_ps(float(-1.0 / k.s2)), vx = _mm256_load_ps(x);
    const __m256 first = _mm256_fmadd_ps(_mm256_add_ps(vx, vx), _mm256_set1_ps(s),
                                         _mm256_set1_ps(s * s));  // (x + s)^2 - x^2
    _mm256_storeu_ps(g0, expLanes(_mm256_mul_ps(_mm256_load_ps(q), minusInvS2)));
    _mm256_storeu_ps(r0, expLanes(_mm256_mul_ps(first, minusInvS2)));
}
FOOTPRINT_LANES_END
#endif

void perRay(const FieldGrid<4>& g, const Taper& k, const Line& l, double s, int n,
            std::vector<Reach>& reach, std::vector<float>& acc, std::vector<double>& out) {
    gatherReach(g, k, l, s, n, reach);
    std::fill(acc.begin(), acc.end(), 0.0f);
    const float fs = float(s), step = float(std::exp(-2.0 * s * s / k.s2));
    for (std::size_t b = 0; b < reach.size(); b += 8) {
        const int count = int(std::min<std::size_t>(8, reach.size() - b));
        float g0[8], r0[8];
#if defined(FOOTPRINT_HAVE_LANES)
        if (footprint::cpuHasLanes()) {
            startLanes(&reach[b], count, k, fs, g0, r0);
        } else
#endif
            for (int q = 0; q < count; ++q) {
                const double x = reach[b + q].x0;
                g0[q] = float(std::exp(-(reach[b + q].d2 + x * x) / k.s2));
                r0[q] = float(std::exp(-(2 * x * s + s * s) / k.s2));
            }
        for (int q = 0; q < count; ++q)
            addReach(reach[b + q], k, fs, step, g0[q], r0[q], acc.data());
    }
    for (std::size_t q = 0; q < out.size(); ++q) out[q] = acc[q];
}

}  // namespace

int main(int argc, char** argv) {
    const int rays = argc > 1 ? std::atoi(argv[1]) : 1000;
    const double s = argc > 2 ? std::atof(argv[2]) : 0.25;
    if (rays < 1 || !(s >= 0.01 && s <= 4)) {
        std::fprintf(stderr, "usage: bench_ray_sum [RAYS >= 1] [SPACING in 0.01..4]\n");
        return 2;
    }
    const footprint::Kernel kernel = footprint::Kernel::defaultKernel();
    const SeparableGaussian gauss(kernel);
    const double r = kernel.radius(), s2 = 2 * kernel.sigma() * kernel.sigma();
    const double eR = std::exp(-r * r / s2), nrm = kernel.normalisation();
    const Taper taper{r * r, s2, nrm, nrm * eR * (1 + r * r / s2), nrm * eR / s2};
    const int dim = 128, n = int(100.0 / s) + 1;
    FieldGrid<4> grid;
    grid.dims = glm::ivec3(dim);
    grid.radius = r;
    grid.gauss = &gauss;
    grid.values.resize(std::size_t(dim) * dim * dim * 4);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (float& x : grid.values) x = unit(rng);
    std::normal_distribution<double> normal;
    std::vector<Line> lines(static_cast<std::size_t>(rays));
    for (Line& l : lines) {
        l.v = glm::normalize(glm::dvec3(normal(rng), normal(rng), normal(rng)));
        const glm::dvec3 c =
            glm::dvec3(dim / 2.0) + 4.0 * glm::dvec3(normal(rng), normal(rng), normal(rng));
        l.p0 = c - 50.0 * l.v;
    }
    std::vector<double> a(std::size_t(n) * 4), b(a.size());
    std::vector<float> acc(a.size());
    std::vector<Reach> reach;
    auto window = [&](const Line& l, std::vector<double>& out) {
        for (int q = 0; q < n; ++q) grid.eval(l.p0 + (q * s) * l.v, &out[std::size_t(q) * 4]);
    };
    double diff = 0, peak = 0, sink = 0;
    for (const Line& l : lines) {
        window(l, a);
        perRay(grid, taper, l, s, n, reach, acc, b);
        for (std::size_t q = 0; q < a.size(); ++q) {
            diff = std::max(diff, std::abs(a[q] - b[q]));
            peak = std::max(peak, std::abs(a[q]));
        }
    }
    std::printf("%d rays x %d samples, spacing %g: max |window - per ray| %.2g of %.2g\n", rays, n,
                s, diff, peak);
    for (int round = 0; round < 3; ++round)
        for (int way = 0; way < 3; ++way) {
            const double t0 = cpuNs();
            for (const Line& l : lines) {
                if (way == 0)
                    window(l, a);
                else if (way == 1)
                    perRay(grid, taper, l, s, n, reach, acc, a);
                else
                    gatherReach(grid, taper, l, s, n, reach);
                sink += a[std::size_t(n / 2) * 4];
            }
            std::printf("%-8s %6.1f ns per sample\n",
                        way == 0   ? "window"
                        : way == 1 ? "per ray"
                                   : "gather",
                        (cpuNs() - t0) / (double(rays) * n));
        }
    return sink == 42.0 ? 1 : 0;  // keeps the sums from being optimised away
}
