#pragma once
// The Westover footprint table: the line integral of one kernel through the plane at
// perpendicular distance r from its centre,
//
//     fp(r) = integral_{-L}^{L} h(sqrt(r^2 + z^2)) dz,   L = sqrt(R^2 - r^2),
//
// tabulated once by adaptive Gauss-Kronrod (7/15) quadrature (split at the kernel's
// kinks) and indexed by r^2 so that lookups need no sqrt (L. Westover, "Footprint
// evaluation for volume rendering", SIGGRAPH 1990). For a ray with direction v in index
// space the world-length integral is fp(|u_perp|) / |v| (see ellipse.h).
//
// Accuracy (default Gaussian, see tests and tools/bench/bench_footprint): linear
// interpolation in r^2 has error <= h^2/8 max|fp''|, h = R^2 / resolution; the C1 taper
// of the kernel keeps fp smooth up to R. At the default 4096 entries (16 KiB, fits L1)
// the max error vs the closed form is 2.3e-7 of the peak; the tests assert <= 1e-6.
#include <cstddef>
#include <vector>

#include "footprint/kernel.h"

namespace footprint {

class FootprintTable {
  public:
    /// `resolution` intervals uniformly spaced in r^2 over [0, R^2] (resolution + 1 samples
    /// plus a zero guard). Throws std::invalid_argument unless 2 <= resolution <= 2^24.
    explicit FootprintTable(const Kernel& kernel, int resolution = kDefaultResolution);
    static constexpr int kDefaultResolution = 4096;

    /// fp at squared distance r2 (voxels^2), linearly interpolated in r^2; 0 for r2 >= R^2
    /// (and for NaN or +inf); negative r2 (rounding of a quadratic form) is treated as 0.
    /// Branch-free (two clamps, two loads), so loops over it can vectorise.
    float lookup(float r2) const {
        float t = r2 * invStep_;
        t = t < tMax_ ? t : tMax_;  // r2 >= R^2, +inf and NaN land on the zero at R
        t = t > 0.0f ? t : 0.0f;
        const int i = int(t);
        const float f = t - float(i);
        const float v0 = values_[i], v1 = values_[i + 1];
        return v0 + f * (v1 - v0);
    }
    /// fp(r) by direct adaptive quadrature (slow; for tests and table building).
    double exact(double r) const;

    const Kernel& kernel() const { return kernel_; }
    double radius() const { return kernel_.radius(); }
    int resolution() const { return resolution_; }
    float peak() const { return values_.empty() ? 0.0f : values_[0]; }
    std::size_t bytes() const { return values_.size() * sizeof(float); }

    /// R^2: fp is 0 at and beyond it.
    float r2Max() const { return r2Max_; }

  private:
    friend class FootprintLanes;  // footprint/lanes.h: the same lookup, 8 lanes at a time
    Kernel kernel_;
    int resolution_ = 0;
    float r2Max_ = 0, invStep_ = 0, tMax_ = 0;
    std::vector<float> values_;  // resolution + 2 entries (a guard for i + 1)
};

}  // namespace footprint
