// Piecewise-polynomial footprint evaluation (see footprint_poly.h).
#include "footprint/footprint_poly.h"

#include <algorithm>
#include <cmath>

#include "chebyshev.h"

namespace footprint {

FootprintPoly::FootprintPoly(const FootprintTable& table) {
    r2Max_ = table.r2Max();
    segScale_ = kSegments / r2Max_;
    const double peak = std::max<double>(table.peak(), 1e-30);
    const double width = double(r2Max_) / kSegments;
    for (degree_ = 3; degree_ < kMaxCoefficients; ++degree_) {
        c_ = {};
        for (int s = 0; s < kSegments; ++s) {
            auto f = [&](double u) {
                return double(table.lookup(float(width * (s + 0.5 * (u + 1)))));
            };
            const auto p = detail::chebyshevInterpolant<kMaxCoefficients>(f, degree_);
            // Stored highest degree first, padded so Horner always runs kMaxCoefficients steps.
            for (int k = 0; k <= degree_; ++k) c_[kMaxCoefficients - 1 - k][s] = float(p[k]);
        }
        maxError_ = 0;
        for (int n = 0; n <= 8192; ++n) {
            const float r2 = float(r2Max_ * n / 8192.0) * 0.999999f;
            maxError_ =
                std::max(maxError_, std::abs(double((*this)(r2)) - table.lookup(r2)) / peak);
        }
        if (maxError_ <= kTolerance) break;
    }
    degree_ = std::min(degree_, kMaxCoefficients - 1);
}

float FootprintPoly::operator()(float r2) const {
    if (!(r2 < r2Max_)) return 0.0f;
    const float s = std::max(r2, 0.0f) * segScale_;
    const int seg = std::min(int(s), kSegments - 1);
    const float u = 2.0f * (s - float(seg)) - 1.0f;
    float p = c_[0][seg];
    for (int k = 1; k < kMaxCoefficients; ++k) p = p * u + c_[k][seg];
    return p;
}

}  // namespace footprint
