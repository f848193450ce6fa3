#pragma once
// Internal: piecewise-polynomial fits shared by FootprintPoly and GaussianSlab.
#include <array>
#include <cmath>

namespace footprint::detail {

/// Monomial coefficients (ascending) of the degree-d polynomial (d < N) interpolating f at
/// the d + 1 Chebyshev nodes of [-1, 1] (Newton divided differences, then expansion).
template <int N, class F>
std::array<double, N> chebyshevInterpolant(F&& f, int d) {
    constexpr double kPi = 3.14159265358979323846;
    const int n = d + 1;
    double x[N] = {}, y[N] = {};
    for (int k = 0; k < n; ++k) {
        x[k] = std::cos(kPi * (k + 0.5) / n);
        y[k] = f(x[k]);
    }
    for (int j = 1; j < n; ++j)
        for (int k = n - 1; k >= j; --k) y[k] = (y[k] - y[k - 1]) / (x[k] - x[k - j]);
    std::array<double, N> p{};  // ascending powers
    p[0] = y[n - 1];
    for (int k = n - 2; k >= 0; --k) {  // p = p * (u - x_k) + y_k
        for (int m = n - 1; m >= 1; --m) p[m] = p[m - 1] - x[k] * p[m];
        p[0] = -x[k] * p[0] + y[k];
    }
    return p;
}

}  // namespace footprint::detail
