#pragma once
// The median of a sample, the one the analyses (popping, its report, study) share.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace splat::analysis {

/// The median of `v` (the mean of the two middle values for an even count); 0 when empty.
inline double median(std::vector<double> v) {
    if (v.empty()) return 0;
    const std::size_t m = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + m, v.end());
    const double hi = v[m];
    if (v.size() % 2) return hi;
    return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + m));
}

/// The median of the finite values of `v`; NaN when there are none.
inline double finiteMedian(std::vector<double> v) {
    v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }),
            v.end());
    return v.empty() ? std::numeric_limits<double>::quiet_NaN() : median(std::move(v));
}

}  // namespace splat::analysis
