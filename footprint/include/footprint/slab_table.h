#pragma once
// Mueller's slab sections: the cumulative line integral of one kernel,
//   C(r, z) = integral_{-R}^{z} h(sqrt(r^2 + z'^2)) dz',
// tabulated over (r^2, z) so that the part of a kernel between depths z0 < z1 (kernel
// units, relative to the point of closest approach) is C(r, z1) - C(r, z0).
#include <cstddef>
#include <vector>

#include "footprint/kernel.h"

namespace footprint {

class SlabTable {
public:
    SlabTable(const Kernel& kernel, int radialResolution = kDefaultRadial,
              int depthResolution = kDefaultDepth);
    static constexpr int kDefaultRadial = 512;
    static constexpr int kDefaultDepth = 512;

    /// C(r, z) for r2 = r^2; bilinear in (r^2, z); z is clamped to [-R, R]
    /// (C = 0 below, the full footprint above); 0 for r2 >= R^2.
    float cumulative(float r2, float z) const;
    /// Section between depths z0 and z1 (kernel units): C(r, z1) - C(r, z0).
    float section(float r2, float z0, float z1) const {
        return cumulative(r2, z1) - cumulative(r2, z0);
    }
    /// C(r, z) by direct quadrature (slow; for tests).
    double exact(double r, double z) const;

    const Kernel& kernel() const { return kernel_; }
    double radius() const { return kernel_.radius(); }
    std::size_t bytes() const { return values_.size() * sizeof(float); }

private:
    Kernel kernel_;
    int nr_ = 0, nz_ = 0;
    float r2Max_ = 0, invR2Step_ = 0, invZStep_ = 0, zMin_ = 0;
    std::vector<float> values_;  // (nr + 2) x (nz + 2), z fastest
};

}  // namespace footprint
