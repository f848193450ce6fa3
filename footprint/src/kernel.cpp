#include "footprint/kernel.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "quadrature.h"

namespace footprint {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string num(double v) {
    std::ostringstream s;
    s.precision(6);
    s << v;
    return s.str();
}

// phi(x) = e^x - 1 - x without cancellation for small x.
double phi(double x) {
    if (x >= 1.0) return std::expm1(x) - x;
    double term = x * x * 0.5, sum = 0;
    for (int k = 3; k < 24 && term > 1e-20 * sum; ++k) {
        sum += term;
        term *= x / k;
    }
    return sum + term;
}

double bspline3(double x) {
    if (x < 1.0) return 2.0 / 3.0 - x * x + 0.5 * x * x * x;
    if (x < 2.0) {
        const double y = 2.0 - x;
        return y * y * y / 6.0;
    }
    return 0.0;
}

}  // namespace

double Kernel::raw(double u) const {
    u = std::abs(u);
    if (!(u < radius_)) return 0.0;
    if (type_ == KernelType::CubicBSpline) return bspline3(u / sigma_);
    const double s2 = 2.0 * sigma_ * sigma_;
    const double q = u * u;
    const double x = (radius_ * radius_ - q) / s2;  // >= 0
    // exp(-q/s2) - e_R (1 + x) = e_R (e^x - 1 - x): the second form for small x avoids
    // cancellation near R, the first avoids overflow of e^x when R / sigma is large.
    if (x < 1.0) return offset_ * phi(x);
    return std::exp(-q / s2) - offset_ * (1.0 + x);
}

double Kernel::operator()(double u) const { return norm_ * raw(u); }

Kernel Kernel::defaultKernel() { return gaussian(kDefaultSigma, kDefaultRadius); }

Kernel Kernel::gaussian(double sigma, double radius) {
    if (!std::isfinite(sigma) || !(sigma > 0))
        throw std::invalid_argument(
            "gaussian kernel: sigma must be a positive finite number "
            "of voxels, got " +
            num(sigma));
    if (!std::isfinite(radius) || !(radius >= 0.5) || !(radius <= kMaxRadius))
        throw std::invalid_argument("gaussian kernel: radius must be in [0.5, 64] voxels, got " +
                                    num(radius));
    if (radius / sigma > 40.0)
        throw std::invalid_argument("gaussian kernel: sigma " + num(sigma) +
                                    " is too small for radius " + num(radius) +
                                    " (radius / sigma must be <= 40)");
    if (sigma / radius > 1e4)
        throw std::invalid_argument("gaussian kernel: sigma " + num(sigma) +
                                    " is too large for radius " + num(radius) +
                                    " (sigma / radius must be <= 1e4)");
    Kernel k;
    k.type_ = KernelType::Gaussian;
    k.sigma_ = sigma;
    k.radius_ = radius;
    k.offset_ = std::exp(-radius * radius / (2.0 * sigma * sigma));
    k.norm_ = 1.0;
    // N = 1 / (4 pi int_0^R g(u) u^2 du); g is smooth on [0, R].
    const double g0 = k.raw(0.0);
    const double m = detail::integrate([&](double u) { return k.raw(u) * u * u; }, 0.0, radius,
                                       1e-15 * g0 * radius * radius * radius);
    k.norm_ = 1.0 / (4.0 * kPi * m);
    return k;
}

Kernel Kernel::cubicBSpline(double scale) {
    if (!std::isfinite(scale) || !(scale >= 0.25) || !(scale <= 32.0))
        throw std::invalid_argument(
            "bspline kernel: scale must be in [0.25, 32] voxels "
            "(radius = 2 scale), got " +
            num(scale));
    Kernel k;
    k.type_ = KernelType::CubicBSpline;
    k.sigma_ = scale;
    k.radius_ = 2.0 * scale;
    k.offset_ = 0.0;
    // 4 pi int_0^2 B3(x) x^2 dx = 4 pi / 6.
    k.norm_ = 3.0 / (2.0 * kPi * scale * scale * scale);
    return k;
}

Kernel Kernel::fromName(const std::string& name, double sigma, double radius) {
    std::string n;
    for (char c : name) n += char(std::tolower(static_cast<unsigned char>(c)));
    auto check = [&](double v, const char* what) {
        if (std::isnan(v) || std::isinf(v) || v < 0)
            throw std::invalid_argument("kernel '" + name + "': " + what +
                                        " must be a positive finite number (0 = default), got " +
                                        num(v));
    };
    check(sigma, "sigma");
    check(radius, "radius");
    if (n == "gaussian" || n == "gauss") {
        return gaussian(sigma == 0 ? kDefaultSigma : sigma, radius == 0 ? kDefaultRadius : radius);
    }
    if (n == "bspline" || n == "b-spline" || n == "cubic-bspline" || n == "cubic") {
        double scale = kDefaultBSplineScale;
        if (sigma > 0 && radius > 0) {
            if (std::abs(radius - 2.0 * sigma) > 1e-9 * radius)
                throw std::invalid_argument("kernel 'bspline': radius must be 2 * scale (scale " +
                                            num(sigma) + ", radius " + num(radius) +
                                            "); give only one of them");
            scale = sigma;
        } else if (sigma > 0) {
            scale = sigma;
        } else if (radius > 0) {
            scale = radius / 2.0;
        }
        return cubicBSpline(scale);
    }
    std::string list;
    for (const auto& s : names()) list += (list.empty() ? "" : ", ") + s;
    throw std::invalid_argument("unknown kernel '" + name + "' (known: " + list + ")");
}

std::vector<std::string> Kernel::names() { return {"gaussian", "bspline"}; }

std::string Kernel::name() const {
    if (type_ == KernelType::CubicBSpline)
        return "bspline(scale=" + num(sigma_) + ", R=" + num(radius_) + ")";
    return "gaussian(sigma=" + num(sigma_) + ", R=" + num(radius_) + ")";
}

double Kernel::variance() const {
    // integral u_x^2 h = (1/3) integral |u|^2 h = (4 pi / 3) integral_0^R u^4 h(u) du, by
    // composite Simpson on 4096 intervals (h is C1 at R, the error is far below 1e-9).
    const int n = 4096;
    const double du = radius_ / n;
    double sum = 0;
    for (int k = 0; k <= n; ++k) {
        const double u = k * du;
        const double w = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
        sum += w * u * u * u * u * (*this)(u);
    }
    return 4.0 * 3.14159265358979323846 / 3.0 * sum * du / 3.0;
}

double Kernel::partitionOfUnityRipple(int samples) const {
    if (samples < 2 || samples > 1000)
        throw std::invalid_argument("partitionOfUnityRipple: samples must be in [2, 1000]");
    const int ext = int(std::ceil(radius_)) + 1;
    double worst = 0;
    for (int a = 0; a < samples; ++a)
        for (int b = 0; b <= a; ++b)  // the sum is symmetric under axis permutations
            for (int c = 0; c <= b; ++c) {
                const double p[3] = {0.5 * a / (samples - 1), 0.5 * b / (samples - 1),
                                     0.5 * c / (samples - 1)};
                double sum = 0;
                for (int i = -ext; i <= ext + 1; ++i)
                    for (int j = -ext; j <= ext + 1; ++j) {
                        const double dx = p[0] - i, dy = p[1] - j;
                        const double d2 = dx * dx + dy * dy;
                        if (d2 >= radius_ * radius_) continue;
                        for (int k = -ext; k <= ext + 1; ++k) {
                            const double dz = p[2] - k;
                            sum += (*this)(std::sqrt(d2 + dz * dz));
                        }
                    }
                worst = std::max(worst, std::abs(sum - 1.0));
            }
    return worst;
}

}  // namespace footprint
