// Closed forms of the tapered Gaussian's footprint (see closed_form.h). With
// h(u) = c (exp(-u^2 / 2s^2) - e_R (1 + (R^2 - u^2) / 2s^2)), e_R = exp(-R^2 / 2s^2), the
// line at distance r meets the support over |z| <= L = sqrt(R^2 - r^2); the Gaussian term
// integrates to erf, the taper to a cubic in z.
#include "footprint/closed_form.h"

#include <algorithm>
#include <cmath>

namespace footprint {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

double gaussianFootprintClosedForm(const Kernel& k, double r) {
    return gaussianCumulativeClosedForm(k, r, k.radius());
}

double gaussianCumulativeClosedForm(const Kernel& k, double r, double z) {
    const double s = k.sigma(), R = k.radius();
    if (r >= R) return 0;
    const double L = std::sqrt(R * R - r * r);
    z = std::clamp(z, -L, L);
    const double eR = std::exp(-R * R / (2 * s * s));
    const double q = 1 / (s * std::sqrt(2.0));
    const double g = s * std::sqrt(kPi / 2) * std::exp(-r * r / (2 * s * s)) *
                     (std::erf(z * q) + std::erf(L * q));
    const double lin = eR * (z + L);
    const double quad = eR / (2 * s * s) * (L * L * (z + L) - (z * z * z + L * L * L) / 3);
    return k.normalisation() * (g - lin - quad);
}

}  // namespace footprint
