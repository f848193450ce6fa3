#pragma once
// Mueller's slab sections: the cumulative line integral of one kernel,
//
//     C(r, z) = integral_{-R}^{z} h(sqrt(r^2 + z'^2)) dz',
//
// so that the part of a kernel between depths z0 < z1 (kernel units, i.e. index-space
// length along the ray, relative to the point of closest approach) is
// C(r, z1) - C(r, z0) (K. Mueller and R. Crawfis, "Eliminating popping artifacts in
// sheet buffer-based splatting", IEEE Visualization 1998; K. Mueller, T. Moeller and
// R. Crawfis, "Splatting without the blur", IEEE Visualization 1999).
//
// Storage: C = fp(r) * F(r, z), where fp is a FootprintTable (1D in r^2, default
// resolution) and F = C / fp in [0, 1] is the fraction of the footprint below z, stored on
// a (r^2, z) grid and interpolated bilinearly. For an untruncated Gaussian F = Phi(z/sigma)
// does not depend on r at all, so F needs few radial samples; and F(r, R) = 1 exactly, so
//   * C(r, z >= R) equals FootprintTable::lookup(r^2) bit for bit, and
//   * sections of any partition of [-R, R] telescope to the full footprint (to float
//     rounding, ~1e-7 of the peak).
// A single section's error is the bilinear error of F times fp: at the defaults
// (128 x 1024, 1 MiB with rows interleaved in pairs, + 16 KiB) it is 1.7e-6 of the
// peak for the default Gaussian (the tests assert 5e-6) and 4.2e-5 for the cubic B-spline (asserted
// 1e-4: its u^3 term is not smooth in r^2 at the centre); see tools/bench/bench_footprint for other
// resolutions.
#include <cstddef>
#include <optional>
#include <vector>

#include "footprint/footprint_table.h"
#include "footprint/gaussian_slab.h"
#include "footprint/kernel.h"

namespace footprint {

class SlabTable {
  public:
    /// `radialResolution` intervals in r^2 over [0, R^2], `depthResolution` intervals in z
    /// over [-R, R]. Throws std::invalid_argument unless both are in [2, 2^14].
    SlabTable(const Kernel& kernel, int radialResolution = kDefaultRadial,
              int depthResolution = kDefaultDepth);
    static constexpr int kDefaultRadial = 128;
    static constexpr int kDefaultDepth = 1024;

    /// C(r, z) for r2 = r^2; bilinear in (r^2, z) for the fraction F; z is clamped to
    /// [-R, R] (C = 0 below, the full footprint above; NaN z counts as below); 0 for
    /// r2 >= R^2.
    float cumulative(float r2, float z) const { return footprint_.lookup(r2) * fraction(r2, z); }
    /// Section between depths z0 and z1 (kernel units): C(r, z1) - C(r, z0).
    float section(float r2, float z0, float z1) const {
        return footprint_.lookup(r2) * (fraction(r2, z1) - fraction(r2, z0));
    }
    /// F(r, z) = C(r, z) / fp(r) in [0, 1], bilinearly interpolated (0 below -R, 1 above R).
    float fraction(float r2, float z) const {
        float rr = (r2 > 0.0f ? r2 : 0.0f) * invR2Step_;
        rr = rr < nrf_ ? rr : nrf_;
        float zz = (z - zMin_) * invZStep_;
        zz = zz > 0.0f ? zz : 0.0f;  // also maps NaN to 0
        zz = zz < nzf_ ? zz : nzf_;
        const int i = int(rr), j = int(zz);
        const float fr = rr - float(i), fz = zz - float(j);
        const float* p = values_.data() + 2 * (std::size_t(i) * stride_ + j);
        const float a = p[0] + fz * (p[2] - p[0]);
        const float b = p[1] + fz * (p[3] - p[1]);
        return a + fr * (b - a);
    }
    /// Depths where fraction() is exactly 0 or 1 (what the interpolation reads there is all
    /// 0 or all 1, with one grid step of margin): for every r2' >= r2 (as fraction() and
    /// FractionLanes clamp and index it), F(r2', z) == 0 for z <= zeroBelow and
    /// F(r2', z) == 1 for z >= oneAbove. The kernel's chord shrinks as r grows, so a row of
    /// pixels whose smallest r^2 is r2 needs no lookup at the depths outside (zeroBelow,
    /// oneAbove): the image-aligned splatter cuts each kernel only where F varies.
    struct Saturation {
        float zeroBelow, oneAbove;
    };
    Saturation saturation(float r2) const {
        float rr = (r2 > 0.0f ? r2 : 0.0f) * invR2Step_;
        rr = rr < nrf_ ? rr : nrf_;
        return saturation_[std::size_t(int(rr))];
    }
    /// C(r, z) by direct adaptive quadrature (slow; for tests).
    double exact(double r, double z) const;

    /// The kernel's closed form (gaussian_slab.h), exact where the grid interpolates; null
    /// for kernels without one (the image-aligned splatter then reads the grid).
    const GaussianSlab* closedForm() const { return closed_ ? &*closed_ : nullptr; }

    const Kernel& kernel() const { return kernel_; }
    const FootprintTable& footprint() const { return footprint_; }
    double radius() const { return kernel_.radius(); }
    int radialResolution() const { return nr_; }
    int depthResolution() const { return nz_; }
    /// Memory of the fraction grid plus the footprint table.
    std::size_t bytes() const { return values_.size() * sizeof(float) + footprint_.bytes(); }

  private:
    friend class FractionLanes;  // footprint/lanes.h: the same fraction(), 8 lanes at a time
    Kernel kernel_;
    FootprintTable footprint_;
    int nr_ = 0, nz_ = 0, stride_ = 0;
    float r2Max_ = 0, invR2Step_ = 0, invZStep_ = 0, zMin_ = 0, nrf_ = 0, nzf_ = 0;
    // F on the (nr + 2) x (nz + 2) grid (z fastest, guards for + 1) with rows i and i + 1
    // interleaved: (F(i, j), F(i + 1, j)) at 2 (i stride + j), i in [0, nr]. The four
    // values of one bilinear lookup are 16 contiguous bytes (FractionLanes: one load per
    // lane instead of four gathered floats).
    std::vector<float> values_;
    std::vector<Saturation> saturation_;  // per grid row 0..nr (the row below r^2)
    std::optional<GaussianSlab> closed_;
};

}  // namespace footprint
