#pragma once
// The Westover footprint table: the line integral of one kernel through the plane at
// perpendicular distance r from its centre, fp(r) = integral h(sqrt(r^2 + z^2)) dz,
// tabulated once by accurate quadrature and indexed by r^2 so that lookups need no sqrt.
#include <cstddef>
#include <vector>

#include "footprint/kernel.h"

namespace footprint {

class FootprintTable {
public:
    /// `resolution` entries uniformly spaced in r^2 over [0, R^2].
    explicit FootprintTable(const Kernel& kernel, int resolution = kDefaultResolution);
    static constexpr int kDefaultResolution = 4096;

    /// fp at squared distance r2 (voxels^2), linearly interpolated in r^2; 0 for r2 >= R^2.
    float lookup(float r2) const {
        if (!(r2 < r2Max_)) return 0.0f;
        const float t = r2 * invStep_;
        const int i = int(t);
        const float f = t - float(i);
        return values_[i] + f * (values_[i + 1] - values_[i]);
    }
    /// fp(r) by direct adaptive quadrature (slow; for tests and table building).
    double exact(double r) const;

    const Kernel& kernel() const { return kernel_; }
    double radius() const { return kernel_.radius(); }
    int resolution() const { return resolution_; }
    float peak() const { return values_.empty() ? 0.0f : values_[0]; }
    std::size_t bytes() const { return values_.size() * sizeof(float); }

private:
    Kernel kernel_;
    int resolution_ = 0;
    float r2Max_ = 0, invStep_ = 0;
    std::vector<float> values_;  // resolution + 2 entries (a guard for i + 1)
};

}  // namespace footprint
