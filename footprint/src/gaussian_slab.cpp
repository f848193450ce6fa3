// Closed-form slab sections of the Gaussian kernel (see gaussian_slab.h).
#include "footprint/gaussian_slab.h"

#include <algorithm>
#include <cmath>

#include "chebyshev.h"

namespace footprint {

std::optional<GaussianSlab> GaussianSlab::of(const Kernel& kernel) {
    if (kernel.type() != KernelType::Gaussian || !(kernel.radius() >= 1.5 * kernel.sigma()))
        return std::nullopt;
    constexpr double kPi = 3.14159265358979323846;
    const double sigma = kernel.sigma(), R = kernel.radius();
    GaussianSlab g;
    const double k = 1.0 / (2.0 * sigma * sigma), eR = std::exp(-k * R * R);
    g.r2Max_ = float(R * R);
    g.k_ = float(k);
    g.eR_ = float(eR);
    g.alpha_ = float(sigma * std::sqrt(kPi / 2.0));
    g.s_ = float(1.0 / (sigma * std::sqrt(2.0)));
    g.c3_ = float(eR * k / 3.0);
    g.norm_ = float(kernel.normalisation());
    const double xMax = std::min(R / (sigma * std::sqrt(2.0)), 4.5);
    g.xMax_ = float(xMax);
    g.segScale_ = float(kSegments / xMax);
    const double width = xMax / kSegments;
    for (int s = 0; s < kSegments; ++s) {
        const auto p = detail::chebyshevInterpolant<kCoefficients>(
            [&](double u) { return std::erf(width * (s + 0.5 * (u + 1))); }, kCoefficients - 1);
        for (int d = 0; d < kCoefficients; ++d) g.c_[kCoefficients - 1 - d][s] = float(p[d]);
    }
    for (int n = 0; n <= 8192; ++n) {
        const double x = xMax * n / 8192.0;
        g.maxErfError_ = std::max(g.maxErfError_, std::abs(double(g.erf(float(x))) - std::erf(x)));
    }
    return g;
}

float GaussianSlab::erf(float x) const {
    const float ax = std::min(std::abs(x), xMax_);  // (NaN -> xMax)
    const float t = ax * segScale_;
    const int seg = std::min(int(t), kSegments - 1);
    const float u = 2.0f * (t - float(seg)) - 1.0f;
    float p = c_[0][seg];
    for (int d = 1; d < kCoefficients; ++d) p = p * u + c_[d][seg];
    return std::copysign(p, x);
}

GaussianSlab::Radial GaussianSlab::radial(float r2) const {
    Radial r;
    const float l2 = std::max(r2Max_ - std::max(r2, 0.0f), 0.0f);
    r.a = alpha_ * std::exp(-k_ * std::max(r2, 0.0f));
    r.b = eR_ * (1.0f + k_ * l2);
    r.l = std::sqrt(l2);
    r.pl = r.a * erf(r.l * s_) + r.l * (c3_ * l2 - r.b);
    return r;
}

float GaussianSlab::at(const Radial& r, float z) const {
    const float zc = z > -r.l ? (z < r.l ? z : r.l) : -r.l;  // NaN -> -L
    return r.a * erf(zc * s_) + zc * (c3_ * zc * zc - r.b);
}

float GaussianSlab::fraction(float r2, float z0, float z1) const {
    const Radial r = radial(r2);
    if (!(r.l > 0.0f && r.pl > 0.0f)) return 0.0f;
    return (at(r, z1) - at(r, z0)) / (2.0f * r.pl);
}

}  // namespace footprint
