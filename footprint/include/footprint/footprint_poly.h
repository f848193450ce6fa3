#pragma once
// A gather-free evaluation of the footprint table for the vectorised inner loop of the
// axis-aligned splatter. fp(r^2) is split into 8 equal segments of r^2 in [0, R^2] and
// each segment is a polynomial of degree <= 7 in the local coordinate u in [-1, 1]
// (Chebyshev interpolation of the table, converted to monomials). Its 8 coefficients of
// one degree sit in one AVX register and are picked per lane with a permute, so a lookup
// costs a few permutes and fused multiply-adds instead of two 8-lane gathers, which are
// slow on the CPUs this runs on. The degree is raised until the polynomial matches the
// table to kTolerance of the peak; maxError() is that measured figure.
#include <array>

#include "footprint/footprint_table.h"

namespace footprint {

class FootprintPoly {
  public:
    static constexpr int kSegments = 8;
    static constexpr int kMaxCoefficients = 8;  // the vector code assumes exactly 8
    static constexpr double kTolerance = 1e-6;  ///< of the peak

    explicit FootprintPoly(const FootprintTable& table);

    /// coefficient k of every segment, highest degree first (Horner order)
    const std::array<std::array<float, kSegments>, kMaxCoefficients>& coefficients() const {
        return c_;
    }
    int degree() const { return degree_; }
    float segmentScale() const { return segScale_; }  ///< segments per unit r^2
    float r2Max() const { return r2Max_; }
    double maxError() const { return maxError_; }  ///< max |poly - table| / peak

    /// Scalar evaluation (tests and tails).
    float operator()(float r2) const;

  private:
    std::array<std::array<float, kSegments>, kMaxCoefficients> c_{};
    int degree_ = 0;
    float segScale_ = 0, r2Max_ = 0;
    double maxError_ = 0;
};

}  // namespace footprint
