// Kernels: normalisation, shape, partition-of-unity ripple, parameter validation.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "footprint/kernel.h"

using footprint::Kernel;
using footprint::KernelType;

namespace {

constexpr double kPi = 3.14159265358979323846;

// 4 pi int_0^R h(u) u^2 du by composite Simpson (independent of the library's quadrature).
double radialIntegral(const Kernel& k, int n = 20000) {
    const double R = k.radius(), h = R / n;
    double s = 0;
    for (int i = 0; i <= n; ++i) {
        const double u = i * h;
        const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
        s += w * k(u) * u * u;
    }
    return 4 * kPi * s * h / 3;
}

// Closed-form normalisation of the C1-tapered Gaussian (see kernel.h).
double gaussianNorm(double sigma, double R) {
    const double eR = std::exp(-R * R / (2 * sigma * sigma));
    const double m =
        sigma * sigma * sigma *
            (std::sqrt(kPi / 2) * std::erf(R / (sigma * std::sqrt(2.0))) - R / sigma * eR) -
        eR * R * R * R / 3 -
        eR / (2 * sigma * sigma) * (R * R * R * R * R / 3 - R * R * R * R * R / 5);
    return 1 / (4 * kPi * m);
}

}  // namespace

TEST_CASE("kernel defaults", "[footprint][kernel]") {
    const Kernel k = Kernel::defaultKernel();
    CHECK(k.type() == KernelType::Gaussian);
    CHECK(k.sigma() == Kernel::kDefaultSigma);
    CHECK(k.radius() == Kernel::kDefaultRadius);
    CHECK(k.radius() <= 2.0);
    CHECK(k.sigma() >= 0.6);
    CHECK(k.sigma() <= 0.8);
    CHECK(k.name() == "gaussian(sigma=0.65, R=2)");
    CHECK(Kernel::names() == std::vector<std::string>{"gaussian", "bspline"});
}

TEST_CASE("kernels integrate to one over R^3", "[footprint][kernel]") {
    for (const Kernel& k :
         {Kernel::defaultKernel(), Kernel::gaussian(0.8, 2), Kernel::gaussian(0.6, 1.5),
          Kernel::gaussian(1.5, 3), Kernel::gaussian(0.05, 2), Kernel::gaussian(1e4, 2),
          Kernel::cubicBSpline(1.0), Kernel::cubicBSpline(0.7)}) {
        INFO(k.name());
        CHECK(radialIntegral(k) == Approx(1.0).epsilon(1e-9));
    }
    for (double sigma : {0.5, 0.65, 0.8, 2.0}) {
        for (double R : {1.0, 2.0, 4.0}) {
            const Kernel k = Kernel::gaussian(sigma, R);
            INFO(k.name());
            // (the closed form cancels badly when sigma > R)
            CHECK(k.normalisation() ==
                  Approx(gaussianNorm(sigma, R)).epsilon(sigma < R ? 1e-12 : 1e-9));
        }
    }
    CHECK(Kernel::cubicBSpline(2.0).normalisation() == Approx(3 / (2 * kPi * 8)).epsilon(1e-15));
}

TEST_CASE("kernel shape: positive, decreasing, zero at and beyond R", "[footprint][kernel]") {
    for (const Kernel& k :
         {Kernel::defaultKernel(), Kernel::cubicBSpline(), Kernel::gaussian(3, 2)}) {
        INFO(k.name());
        const double R = k.radius();
        double prev = k(0);
        CHECK(prev > 0);
        for (int i = 1; i < 1000; ++i) {
            const double v = k(R * i / 1000.0);
            CHECK(v > 0);
            CHECK(v < prev);
            prev = v;
        }
        CHECK(k(R) == 0);
        CHECK(k(std::nextafter(R, 0.0)) >= 0);
        CHECK(k(std::nextafter(R, 0.0)) < 1e-20);
        CHECK(k(R + 1e-9) == 0);
        CHECK(k(1e300) == 0);
        CHECK(k(std::numeric_limits<double>::infinity()) == 0);
        CHECK(k(std::numeric_limits<double>::quiet_NaN()) == 0);
        CHECK(k(-0.5) == k(0.5));
    }
    // The taper is C1: h ~ (R^2 - u^2)^2 near R.
    const Kernel k = Kernel::defaultKernel();
    const double e = 1e-3;
    CHECK(k(2 - e) / k(2 - 2 * e) == Approx(0.25).epsilon(2e-3));
    // Far from R the Gaussian shape is untouched but for the small taper.
    const double eR = std::exp(-4 / (2 * 0.65 * 0.65));
    for (double u : {0.0, 0.5, 1.0, 1.5}) {
        const double x = (4 - u * u) / (2 * 0.65 * 0.65);
        CHECK(k(u) ==
              Approx(k.normalisation() * (std::exp(-u * u / (2 * 0.65 * 0.65)) - eR * (1 + x)))
                  .epsilon(1e-13));
    }
}

TEST_CASE("partition-of-unity ripple", "[footprint][kernel]") {
    // Measured (9^3 samples over the half cell): default Gaussian 6.77e-3,
    // bspline(scale=1) 2.09e-3. sigma = 0.65 is the minimiser for R = 2 (0.60: 8.6e-3,
    // 0.70: 7.8e-3).
    const double g = Kernel::defaultKernel().partitionOfUnityRipple();
    INFO("gaussian ripple " << g);
    CHECK(g < 7.0e-3);
    CHECK(g > 6.0e-3);  // the figure documented in kernel.h
    CHECK(Kernel::gaussian(0.60, 2).partitionOfUnityRipple() > g);
    CHECK(Kernel::gaussian(0.70, 2).partitionOfUnityRipple() > g);
    const double b = Kernel::cubicBSpline().partitionOfUnityRipple();
    INFO("bspline ripple " << b);
    CHECK(b < 2.5e-3);
    // A wide, barely truncated Gaussian is a near-perfect partition of unity.
    CHECK(Kernel::gaussian(1.0, 5).partitionOfUnityRipple(5) < 1e-5);
    CHECK_THROWS_AS(Kernel::defaultKernel().partitionOfUnityRipple(1), std::invalid_argument);
}

TEST_CASE("Kernel::fromName", "[footprint][kernel]") {
    CHECK(Kernel::fromName("gaussian").name() == Kernel::defaultKernel().name());
    CHECK(Kernel::fromName("Gaussian", 0.8).sigma() == 0.8);
    CHECK(Kernel::fromName("gaussian", 0.8).radius() == 2.0);
    CHECK(Kernel::fromName("gaussian", 0, 1.5).sigma() == Kernel::kDefaultSigma);
    CHECK(Kernel::fromName("gaussian", 0, 1.5).radius() == 1.5);
    const Kernel b = Kernel::fromName("bspline");
    CHECK(b.type() == KernelType::CubicBSpline);
    CHECK(b.radius() == 2.0);
    CHECK(Kernel::fromName("bspline", 0.75).radius() == 1.5);
    CHECK(Kernel::fromName("bspline", 0, 3).sigma() == 1.5);
    CHECK(Kernel::fromName("bspline", 1.5, 3).radius() == 3);
    CHECK(Kernel::fromName("bspline").name() == "bspline(scale=1, R=2)");

    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    CHECK_THROWS_AS(Kernel::fromName("box"), std::invalid_argument);
    CHECK_THROWS_WITH(Kernel::fromName("box"), Catch::Contains("unknown kernel 'box'") &&
                                                   Catch::Contains("gaussian, bspline"));
    CHECK_THROWS_WITH(Kernel::fromName("gaussian", -1), Catch::Contains("sigma"));
    CHECK_THROWS_WITH(Kernel::fromName("gaussian", nan), Catch::Contains("sigma"));
    CHECK_THROWS_WITH(Kernel::fromName("gaussian", 0.7, -2), Catch::Contains("radius"));
    CHECK_THROWS_WITH(Kernel::fromName("gaussian", 0.7, inf), Catch::Contains("radius"));
    CHECK_THROWS_WITH(Kernel::fromName("gaussian", 0.7, 65), Catch::Contains("radius"));
    CHECK_THROWS_WITH(Kernel::fromName("gaussian", 0.7, 0.25), Catch::Contains("radius"));
    CHECK_THROWS_WITH(Kernel::fromName("gaussian", 0.01, 2), Catch::Contains("too small"));
    CHECK_THROWS_WITH(Kernel::fromName("gaussian", 1e5, 2), Catch::Contains("too large"));
    CHECK_THROWS_WITH(Kernel::fromName("bspline", 1, 3), Catch::Contains("2 * scale"));
    CHECK_THROWS_AS(Kernel::fromName("bspline", 0, 100), std::invalid_argument);
    CHECK_THROWS_AS(Kernel::fromName("bspline", nan), std::invalid_argument);
    CHECK_THROWS_AS(Kernel::gaussian(0, 2), std::invalid_argument);
    CHECK_THROWS_AS(Kernel::gaussian(-0.7, 2), std::invalid_argument);
    CHECK_THROWS_AS(Kernel::gaussian(nan, 2), std::invalid_argument);
    CHECK_THROWS_AS(Kernel::gaussian(0.7, nan), std::invalid_argument);
    CHECK_THROWS_AS(Kernel::cubicBSpline(0), std::invalid_argument);
    CHECK_THROWS_AS(Kernel::cubicBSpline(inf), std::invalid_argument);
    CHECK_NOTHROW(Kernel::gaussian(0.05, 2));
    CHECK_NOTHROW(Kernel::gaussian(2, 64));
}
