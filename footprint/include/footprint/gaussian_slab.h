#pragma once
// Closed-form slab sections of the Gaussian kernel (kernel.h): exact where SlabTable
// interpolates, and cheaper per footprint pixel. With k = 1 / (2 sigma^2), e_R =
// exp(-k R^2), L = sqrt(R^2 - r^2) the half chord at distance r, and z clamped to [-L, L],
//
//     C(r, z) - C(r, 0) = N P(r^2, z),
//     P(r^2, z) = sigma sqrt(pi / 2) exp(-k r^2) erf(z / (sigma sqrt 2))
//                 - e_R (1 + k (R^2 - r^2)) z + e_R k z^3 / 3,
//
// since dP/dz = exp(-k (r^2 + z^2)) - e_R (1 + k (R^2 - r^2 - z^2)) = h(sqrt(r^2 + z^2)) / N
// (the C1-tapered Gaussian). P is odd in z, so the footprint is 2 N P(r^2, L) and the
// fraction of it between depths z0 < z1 is
//
//     (P(r^2, z1) - P(r^2, z0)) / (2 P(r^2, L)),
//
// which the splatters multiply by the footprint table's fp(r^2): sections of any partition
// of [-R, R] telescope to the table's footprint as SlabTable's do. Per pixel the radial part
// (exp, sqrt, erf(L)) is shared by every slab boundary; per boundary it is one erf, which
// is a piecewise polynomial (8 segments of [0, min(R / (sigma sqrt 2), 4.5)], degree 7,
// Chebyshev interpolation of std::erf; 1 - erf(4.5) = 2e-10): its error is maxErfError(),
// < 2e-7 (tests). When the slab boundaries do not depend on the pixel (tx = ty = 0 in
// ellipse.h: orthographic views of isotropic voxels) the erf of each boundary is the
// splat's, computed once. The fraction's error against quadrature is < 1e-6 of the
// footprint (tests; the default 128 x 1024 SlabTable: 1.7e-6 of the peak).
//
// Only for Gaussians with R >= 1.5 sigma (of() is empty otherwise; the table serves the
// others): as R / sigma falls the three terms of P cancel in float (at R = sigma a section
// is off by 2.7e-6 of the peak).
#include <array>
#include <optional>

#include "footprint/kernel.h"

namespace footprint {

class GaussianSlab {
  public:
    static constexpr int kSegments = 8;
    static constexpr int kCoefficients = 8;

    /// The closed form of `kernel`'s slab sections; empty unless it is a Gaussian with
    /// R >= 1.5 sigma.
    static std::optional<GaussianSlab> of(const Kernel& kernel);

    /// The part of P shared by every depth at one r^2: a = sigma sqrt(pi/2) exp(-k r^2),
    /// b = e_R (1 + k L^2), the half chord l = L and pl = P(r^2, L) (> 0 inside the kernel).
    struct Radial {
        float a, b, l, pl;
    };
    Radial radial(float r2) const;
    /// P(r^2, z) with z clamped to [-L, L] (NaN z counts as -L).
    float at(const Radial& r, float z) const;
    /// (P(z1) - P(z0)) / (2 P(L)) for z0 <= z1: the fraction of the footprint between them
    /// (0 outside the kernel).
    float fraction(float r2, float z0, float z1) const;
    /// erf(x) from the piecewise polynomial (any finite x; +-1 beyond the fitted range).
    float erf(float x) const;
    /// max |erf(x) - std::erf(x)| over the fitted range, measured when built.
    double maxErfError() const { return maxErfError_; }

    float r2Max() const { return r2Max_; }
    /// 1 / (sigma sqrt 2): erf's argument per unit of z.
    float erfScale() const { return s_; }
    /// e_R k / 3, the cubic term's coefficient.
    float cubic() const { return c3_; }

  private:
    friend class GaussianSlabLanes;  // footprint/lanes.h: the same forms, 8 lanes at a time
    GaussianSlab() = default;
    float r2Max_ = 0, k_ = 0, eR_ = 0, alpha_ = 0, s_ = 0, c3_ = 0, norm_ = 1;  // norm_ = N
    float xMax_ = 0, segScale_ = 0;  // erf's fitted range [0, xMax] and segments per unit x
    // coefficient k of every segment, highest degree first (Horner order), as FootprintPoly
    std::array<std::array<float, kSegments>, kCoefficients> c_{};
    double maxErfError_ = 0;
};

}  // namespace footprint
