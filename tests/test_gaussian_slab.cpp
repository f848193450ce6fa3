// The Gaussian kernel's closed-form slab sections (footprint/gaussian_slab.h) against the
// double-precision closed form and quadrature, and its 8-lane evaluation against the scalar.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "footprint/closed_form.h"
#include "footprint/footprint_table.h"
#include "footprint/gaussian_slab.h"
#include "footprint/lanes.h"
#include "footprint/slab_table.h"

using footprint::GaussianSlab;
using footprint::Kernel;

namespace {
const Kernel kKernels[] = {Kernel::defaultKernel(), Kernel::gaussian(1.0, 3.0),
                           Kernel::gaussian(0.5, 4.0), Kernel::gaussian(1.0, 1.5),
                           Kernel::gaussian(0.3, 12.0)};
}  // namespace

TEST_CASE("gaussian slab: only Gaussians with R >= 1.5 sigma have the closed form",
          "[footprint][slab]") {
    CHECK(GaussianSlab::of(Kernel::defaultKernel()).has_value());
    CHECK_FALSE(GaussianSlab::of(Kernel::cubicBSpline()).has_value());
    CHECK_FALSE(GaussianSlab::of(Kernel::gaussian(1.0, 1.4)).has_value());
    CHECK(footprint::SlabTable(Kernel::defaultKernel(), 8, 8).closedForm() != nullptr);
    CHECK(footprint::SlabTable(Kernel::cubicBSpline(), 8, 8).closedForm() == nullptr);
}

TEST_CASE("gaussian slab: erf polynomial within 2e-7 of std::erf", "[footprint][slab]") {
    for (const Kernel& k : kKernels) {
        const GaussianSlab g = *GaussianSlab::of(k);
        INFO(k.name() << ": measured " << g.maxErfError());
        CHECK(g.maxErfError() <= 2e-7);
        // Over the kernel's depths, negative ones too (P uses erf(z / (sigma sqrt 2)) for
        // |z| <= R only).
        const double xMax = k.radius() / (k.sigma() * std::sqrt(2.0));
        double worst = 0;
        for (int n = -4000; n <= 4000; ++n) {
            const double x = xMax * n / 4000.0;
            worst = std::max(worst, std::abs(double(g.erf(float(x))) - std::erf(x)));
        }
        CHECK(worst <= 2e-7);
        CHECK(g.erf(0.0f) == Approx(0.0).margin(1e-7));
    }
}

TEST_CASE("gaussian slab: sections equal the exact integral to 1e-6 of the footprint",
          "[footprint][slab]") {
    for (const Kernel& k : kKernels) {
        const GaussianSlab g = *GaussianSlab::of(k);
        const double R = k.radius();
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> U(0, 1);
        double worst = 0, worstSum = 0;
        for (int trial = 0; trial < 20000; ++trial) {
            const double r2 = R * R * U(rng) * 0.999;
            const double r = std::sqrt(r2);
            double z0 = -1.2 * R + 2.4 * R * U(rng), z1 = -1.2 * R + 2.4 * R * U(rng);
            if (trial % 4 == 0) z1 = z0 + 0.2 * U(rng);  // thin slabs
            if (z0 > z1) std::swap(z0, z1);
            const double fp = footprint::gaussianFootprintClosedForm(k, r);
            const double exact = footprint::gaussianCumulativeClosedForm(k, r, z1) -
                                 footprint::gaussianCumulativeClosedForm(k, r, z0);
            const double peak = footprint::gaussianFootprintClosedForm(k, 0.0);
            worst = std::max(
                worst, std::abs(fp * g.fraction(float(r2), float(z0), float(z1)) - exact) / peak);
            // A partition of the chord into 7 slabs sums to the whole footprint.
            double sum = 0;
            for (int j = 0; j < 7; ++j)
                sum += g.fraction(float(r2), float(-R + 2 * R * j / 7),
                                  float(-R + 2 * R * (j + 1) / 7));
            worstSum = std::max(worstSum, std::abs(sum - 1.0) * fp / peak);
        }
        INFO(k.name() << ": section error " << worst << ", partition " << worstSum
                      << " of the peak");
        CHECK(worst <= 1e-6);
        CHECK(worstSum <= 1e-6);
        CHECK(g.fraction(float(R * R), -1.0f, 1.0f) == 0.0f);  // outside the kernel
    }
}

#if defined(FOOTPRINT_HAVE_LANES)
namespace {
// Largest difference between the lanes and the scalar N P(r^2, z) over r^2 in [0, R^2) and
// z in [-1.2 R, 1.2 R] (the lanes take N P(L), half the footprint, from the caller).
FOOTPRINT_LANES_BEGIN
double laneError(const GaussianSlab& g, const Kernel& k) {
    const footprint::GaussianSlabLanes lanes(g);
    const double R = k.radius(), N = k.normalisation();
    alignas(32) float r2[8], z[8], out[8], half[8], inner[8];
    double worst = 0;
    for (int n = 0; n < 8192; n += 8) {
        for (int l = 0; l < 8; ++l) {
            r2[l] = float(R * R * (n + l) / 8200.0);
            z[l] = float(R * (-1.2 + 2.4 * double((n + l) * 37 % 8192) / 8192.0));
            half[l] = float(N * g.radial(r2[l]).pl);
        }
        const footprint::GaussianSlabLanes::Radial radial =
            lanes.radial(_mm256_load_ps(r2), _mm256_load_ps(half));
        _mm256_store_ps(out, lanes(radial, _mm256_load_ps(z)));
        // A depth inside the chord through the per-boundary form (erf and cubic given).
        alignas(32) float zi[8], e[8], q[8];
        for (int l = 0; l < 8; ++l) {
            const GaussianSlab::Radial s = g.radial(r2[l]);
            zi[l] = 0.5f * s.l * (z[l] / float(1.2 * R));
            e[l] = g.erf(zi[l] * g.erfScale());
            q[l] = float(N) * g.cubic() * zi[l] * zi[l] * zi[l];
        }
        _mm256_store_ps(inner,
                        footprint::GaussianSlabLanes::inside(radial, _mm256_load_ps(zi),
                                                             _mm256_load_ps(e), _mm256_load_ps(q)));
        for (int l = 0; l < 8; ++l) {
            const GaussianSlab::Radial s = g.radial(r2[l]);
            worst = std::max(worst, std::abs(out[l] - N * g.at(s, z[l])));
            worst = std::max(worst, std::abs(inner[l] - N * g.at(s, zi[l])));
        }
    }
    return worst;
}
FOOTPRINT_LANES_END
}  // namespace

TEST_CASE("gaussian slab lanes equal the scalar closed form", "[footprint][slab][stages]") {
    if (!footprint::cpuHasLanes()) {
        WARN("this CPU has no AVX2 + FMA: the scalar closed form is used everywhere");
        return;
    }
    for (const Kernel& k : kKernels) {
        const GaussianSlab g = *GaussianSlab::of(k);
        const double scale = k.normalisation() * k.sigma() * std::sqrt(3.14159265358979 / 2);
        INFO(k.name() << ": " << laneError(g, k) / scale << " of N sigma sqrt(pi/2)");
        CHECK(laneError(g, k) <= 5e-7 * scale);
    }
}
#endif
