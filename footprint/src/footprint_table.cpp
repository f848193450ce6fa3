#include "footprint/footprint_table.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "quadrature.h"

namespace footprint {

FootprintTable::FootprintTable(const Kernel& kernel, int resolution)
    : kernel_(kernel), resolution_(resolution) {
    if (resolution < 2 || resolution > (1 << 24))
        throw std::invalid_argument("FootprintTable: resolution must be in [2, 2^24], got " +
                                    std::to_string(resolution));
    const double R = kernel_.radius();
    const double step = R * R / resolution;
    values_.assign(std::size_t(resolution) + 2, 0.0f);
    for (int i = 0; i < resolution; ++i) values_[i] = float(exact(std::sqrt(i * step)));
    // values_[resolution] = fp(R) = 0 and the guard stay 0.
    r2Max_ = float(R * R);
    invStep_ = float(resolution / (R * R));
    tMax_ = float(resolution);
}

double FootprintTable::exact(double r) const {
    r = std::abs(r);
    const double R = kernel_.radius();
    if (!(r < R)) return 0.0;
    const double r2 = r * r;
    const double L = std::sqrt((R - r) * (R + r));
    const Kernel& k = kernel_;
    auto f = [&](double z) { return k(std::sqrt(r2 + z * z)); };
    // B-spline: the profile changes polynomial piece at u = scale.
    const double s = k.sigma();
    const double zk = (k.type() == KernelType::CubicBSpline && r < s) ? std::sqrt(s * s - r2) : -1;
    const double tol = 1e-14 * k(0.0) * R;
    return 2.0 * detail::integrateSplit(f, 0.0, L, {zk}, tol);
}

}  // namespace footprint
