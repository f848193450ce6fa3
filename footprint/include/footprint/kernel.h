#pragma once
// Radially symmetric reconstruction kernels h(u), u the distance in voxels (index space),
// truncated at radius R and normalised so that the integral of h over R^3 is 1.
#include <string>
#include <vector>

namespace footprint {

enum class KernelType {
    Gaussian,      ///< exp(-u^2 / (2 sigma^2)), truncated at R (see kernel.cpp for the taper)
    CubicBSpline,  ///< the cubic B-spline profile B3(u / scale), compact support R = 2 scale
};

class Kernel {
public:
    /// Default kernel of the renderers.
    static Kernel defaultKernel();
    static Kernel gaussian(double sigma, double radius);
    static Kernel cubicBSpline(double scale = 1.0);
    /// "gaussian" or "bspline"; sigma/radius <= 0 mean "the default for that kernel".
    /// Throws std::invalid_argument on an unknown name or impossible parameters.
    static Kernel fromName(const std::string& name, double sigma = 0, double radius = 0);
    static std::vector<std::string> names();

    KernelType type() const { return type_; }
    std::string name() const;     ///< e.g. "gaussian(sigma=0.8, R=2)"
    double radius() const { return radius_; }
    double sigma() const { return sigma_; }  ///< Gaussian sigma, or B-spline scale

    /// Normalised kernel value at distance u (voxels); 0 for u >= R.
    double operator()(double u) const;

    /// max |sum_i h(p - p_i) - 1| over p in a unit cell of the integer lattice, sampled
    /// on a `samples`^3 grid: the kernel's partition-of-unity ripple.
    double partitionOfUnityRipple(int samples = 9) const;

private:
    KernelType type_ = KernelType::Gaussian;
    double sigma_ = 1.0, radius_ = 2.0, norm_ = 1.0, offset_ = 0.0;
};

}  // namespace footprint
