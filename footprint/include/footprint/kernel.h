#pragma once
// Radially symmetric reconstruction kernels h(u), u the distance in voxels (index space),
// truncated at radius R and normalised so that the integral of h over R^3 is 1.
//
// A volume's reconstructed field is f(x) = sum_i d_i h(|S^-1 (x - x_i)|) (docs/design.md "The
// model"); a constant volume reconstructs to the constant up to the kernel's partition-of-unity
// ripple, max_p |sum_i h(p - p_i) - 1|, which partitionOfUnityRipple() measures and the tests bound
// for the defaults.
//
// Gaussian (default).  With q = u^2 and e_R = exp(-R^2 / (2 sigma^2)),
//
//     h(u) = N [ exp(-q / (2 sigma^2)) - e_R (1 + (R^2 - q) / (2 sigma^2)) ],   u < R,
//
// i.e. the Gaussian minus its first-order Taylor expansion in q = u^2 about q = R^2 (the
// tangent line of the convex function exp(-q / 2 sigma^2)). This C1 taper makes h and
// dh/dq vanish at R, so h ~ (R^2 - q)^2 near the edge and the footprint behaves like
// (R^2 - r^2)^(5/2): a table linear in r^2 then reaches the 1e-6-of-peak accuracy the
// renderers are held to (a hard cut makes fp ~ sqrt(R^2 - r^2), whose linear interpolation
// error near R is ~1e-4 of the peak at any practical resolution). h stays >= 0 (a convex
// function lies above its tangent). The footprint still has a closed form:
//     fp(r) = N [ sigma sqrt(2 pi) exp(-r^2 / 2 sigma^2) erf(L / (sigma sqrt 2))
//                 - 2 L e_R - e_R (4 L^3 / 3) / (2 sigma^2) ],   L = sqrt(R^2 - r^2),
// which the tests compare the tables with.
// Defaults: sigma = 0.65, R = 2 voxels (R <= 2 keeps the splats small; sigma = 0.65
// minimises the ripple for R = 2 among tapered Gaussians: 6.8e-3, see tests).
//
// Cubic B-spline: h(u) = N B3(u / s), B3(x) = 2/3 - x^2 + x^3/2 on [0, 1),
// (2 - x)^3 / 6 on [1, 2), 0 beyond; support R = 2 s, N = 3 / (2 pi s^3). The radial
// profile is not the separable tensor B-spline, so it is not an exact partition of unity
// (ripple 2.1e-3 for s = 1, see tests); it has compact support by itself (no taper
// needed), its footprint has no simple closed form (the tests use quadrature).
//
// References: L. Westover, "Footprint evaluation for volume rendering", SIGGRAPH 1990.
#include <string>
#include <vector>

namespace footprint {

enum class KernelType {
    Gaussian,      ///< exp(-u^2 / (2 sigma^2)), C1-tapered to zero at R (see above)
    CubicBSpline,  ///< the cubic B-spline profile B3(u / scale), compact support R = 2 scale
};

class Kernel {
  public:
    static constexpr double kDefaultSigma = 0.65;
    static constexpr double kDefaultRadius = 2.0;
    static constexpr double kDefaultBSplineScale = 1.0;
    static constexpr double kMaxRadius = 64.0;

    /// Default kernel of the renderers: gaussian(kDefaultSigma, kDefaultRadius).
    static Kernel defaultKernel();
    /// Throws std::invalid_argument unless sigma and radius are finite, radius is in
    /// [0.5, 64] voxels, radius / sigma <= 40 and sigma / radius <= 1e4.
    static Kernel gaussian(double sigma, double radius);
    /// Throws std::invalid_argument unless scale is finite and in [0.25, 32] (R = 2 scale).
    static Kernel cubicBSpline(double scale = 1.0);
    /// "gaussian" or "bspline" (case-insensitive; "cubic-bspline", "b-spline" also work).
    /// sigma / radius == 0 mean "the default for that kernel" (Gaussian: sigma 0.65, R 2,
    /// each independently). For "bspline" sigma is the scale and R = 2 scale: give either
    /// one (or both, consistently). Throws std::invalid_argument on an unknown name or on
    /// impossible parameters (negative, NaN or infinite values, ranges as above).
    static Kernel fromName(const std::string& name, double sigma = 0, double radius = 0);
    static std::vector<std::string> names();

    KernelType type() const { return type_; }
    std::string name() const;  ///< e.g. "gaussian(sigma=0.65, R=2)"
    double radius() const { return radius_; }
    double sigma() const { return sigma_; }         ///< Gaussian sigma, or B-spline scale
    double normalisation() const { return norm_; }  ///< N above

    /// Normalised kernel value at distance u (voxels); 0 for |u| >= R (and for NaN).
    double operator()(double u) const;

    /// The kernel's second moment along one axis, integral of u_x^2 h(u) over R^3 (voxels^2):
    /// the variance of its footprint along any screen direction (default Gaussian: 0.3279,
    /// sigma^2 = 0.4225 less the taper's share; B-spline of scale s: 0.3 s^2; tests/test_ewa).
    /// EWA resampling (ellipse.h, ewaFootprint) widens footprints by this variance.
    double variance() const;

    /// max |sum_i h(p - p_i) - 1| over p in a unit cell of the integer lattice, sampled
    /// on a `samples`^3 grid over [0, 1/2]^3 (by the lattice's reflection symmetry this
    /// covers the whole cell, corners and centre included): the partition-of-unity ripple.
    double partitionOfUnityRipple(int samples = 9) const;

  private:
    double raw(double u) const;  // un-normalised profile
    KernelType type_ = KernelType::Gaussian;
    double sigma_ = 1.0, radius_ = 2.0, norm_ = 1.0, offset_ = 0.0;  // offset_ = e_R
};

}  // namespace footprint
