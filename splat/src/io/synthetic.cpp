// Deterministic synthetic volumes (`synthetic:NAME[:N]`), see synthetic.h.
#include "splat/synthetic.h"

#include <algorithm>
#include <cmath>

#include "splat/error.h"

namespace splat {
namespace {

// 3D Shepp-Logan head phantom: Kak & Slaney, "Principles of Computerized Tomographic
// Imaging" (1988), table 3.2 (p. 102 with the published errata). Each ellipsoid has
// centre (x0, y0, z0), semi-axes (a, b, c), rotation phi (degrees, about the phantom z
// axis) and a density that is added inside it, so the skull shell is 2.0 and the brain
// 2.0 - 0.98 = 1.02. Phantom coordinates are in [-1, 1]^3.
struct Ellipsoid {
    double x0, y0, z0, a, b, c, phi, rho;
};
constexpr Ellipsoid kSheppLogan[10] = {
    {0.00, 0.000, 0.000, 0.6900, 0.920, 0.900, 0, 2.00},
    {0.00, 0.000, 0.000, 0.6624, 0.874, 0.880, 0, -0.98},
    {-0.22, 0.000, -0.250, 0.4100, 0.160, 0.210, 108, -0.02},
    {0.22, 0.000, -0.250, 0.3100, 0.110, 0.220, 72, -0.02},
    {0.00, 0.350, -0.250, 0.2100, 0.250, 0.500, 0, 0.02},
    {0.00, 0.100, -0.250, 0.0460, 0.046, 0.046, 0, 0.02},
    {-0.08, -0.650, -0.250, 0.0460, 0.023, 0.020, 0, 0.01},
    {0.06, -0.650, -0.250, 0.0460, 0.023, 0.020, 90, 0.01},
    {0.06, -0.105, 0.625, 0.0560, 0.040, 0.100, 90, 0.02},
    {0.00, 0.100, 0.625, 0.0560, 0.056, 0.100, 0, -0.02},
};

double phantomAt(double px, double py, double pz) {
    double d = 0;
    for (const Ellipsoid& e : kSheppLogan) {
        double phi = e.phi * M_PI / 180.0;
        double dx = px - e.x0, dy = py - e.y0, dz = pz - e.z0;
        double u = std::cos(phi) * dx + std::sin(phi) * dy;
        double w = -std::sin(phi) * dx + std::cos(phi) * dy;
        double q = (u * u) / (e.a * e.a) + (w * w) / (e.b * e.b) + (dz * dz) / (e.c * e.c);
        if (q <= 1.0) d += e.rho;
    }
    return d;
}

// Marschner & Lobb (1994): rho(x,y,z) = (1 - sin(pi z / 2) + alpha (1 + rho_r(r))) /
// (2 (1 + alpha)), rho_r(r) = cos(2 pi fM cos(pi r / 2)), r = sqrt(x^2 + y^2).
double marschnerLobb(double x, double y, double z) {
    const double fM = 6.0, alpha = 0.25;
    double r = std::sqrt(x * x + y * y);
    double rr = std::cos(2 * M_PI * fM * std::cos(M_PI * r / 2));
    return (1 - std::sin(M_PI * z / 2) + alpha * (1 + rr)) / (2 * (1 + alpha));
}

/// Fills `v`, the box of samples from `lo` on, with f(i, j, k) of the whole volume's indices.
template <typename F>
void fill(Volume& v, const glm::ivec3& lo, F f) {
    for (int k = 0; k < v.dims.z; ++k)
        for (int j = 0; j < v.dims.y; ++j)
            for (int i = 0; i < v.dims.x; ++i)
                v.at(i, j, k) = float(f(lo.x + i, lo.y + j, lo.z + k));
}

}  // namespace

std::vector<std::string> syntheticNames() {
    return {"phantom", "ct-phantom", "blob", "cube", "sphere", "marschner-lobb"};
}

int syntheticDefaultSize(const std::string& name) {
    return name == "phantom" || name == "ct-phantom" ? 128 : 64;
}

Volume makeSynthetic(const std::string& name, int n) {
    return makeSyntheticBrick(name, n, glm::ivec3(0), glm::ivec3(std::clamp(n, 1, 2048)));
}

Volume makeSyntheticBrick(const std::string& name, int n, const glm::ivec3& lo,
                          const glm::ivec3& hi) {
    bool known = false;
    for (const auto& s : syntheticNames()) known = known || s == name;
    if (!known) {
        std::string list;
        for (const auto& s : syntheticNames()) list += (list.empty() ? "" : ", ") + s;
        throw Error("synthetic:" + name + ": unknown synthetic volume (available: " + list + ")");
    }
    if (n < 1 || n > 2048)
        throw Error("synthetic:" + name + ":" + std::to_string(n) +
                    ": size must be between 1 and 2048");
    if (glm::any(glm::lessThan(lo, glm::ivec3(0))) ||
        glm::any(glm::greaterThan(hi, glm::ivec3(n))) || glm::any(glm::lessThanEqual(hi, lo)))
        throw Error("synthetic:" + name + ":" + std::to_string(n) + ": empty or outside brick");
    Volume v = makeVolume(hi - lo, glm::dvec3(1.0), "synthetic:" + name);
    v.origin = glm::dvec3(lo);
    const double c = (n - 1) * 0.5;
    if (name == "phantom" || name == "ct-phantom") {
        // Index -> phantom coordinates: the cube [-1, 1]^3 spans the N samples. The
        // phantom's longest axis (y, semi-axis 0.92) becomes world +z so the head is
        // upright; phantom z becomes world -y (keeps the frame right-handed).
        const double s = 2.0 / n;
        fill(v, lo, [&](int i, int j, int k) {
            return phantomAt((i - c) * s, (k - c) * s, -(j - c) * s);
        });
    } else if (name == "blob") {
        const double sigma = syntheticBlobSigma(n);
        fill(v, lo, [&](int i, int j, int k) {
            double r2 = (i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c);
            return std::exp(-r2 / (2 * sigma * sigma));
        });
    } else if (name == "cube") {
        const double h = n / 4.0;
        fill(v, lo, [&](int i, int j, int k) {
            return std::abs(i - c) < h && std::abs(j - c) < h && std::abs(k - c) < h ? 1.0 : 0.0;
        });
    } else if (name == "sphere") {
        const double r = syntheticSphereRadius(n), w = syntheticSphereEdge();
        fill(v, lo, [&](int i, int j, int k) {
            const double d = std::sqrt((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c));
            const double t = std::clamp((r + w - d) / (2.0 * w), 0.0, 1.0);
            return t * t * t * (10.0 + t * (6.0 * t - 15.0));  // smootherstep
        });
    } else {  // marschner-lobb over [-1, 1]^3, sample 0 at -1 and sample N-1 at +1
        const double s = n > 1 ? 2.0 / (n - 1) : 0.0;
        fill(v, lo, [&](int i, int j, int k) {
            return marschnerLobb(-1 + i * s, -1 + j * s, -1 + k * s);
        });
    }
    if (name == "ct-phantom") {
        // The same head in Hounsfield units: HU = 1000 (d - 1), so air (d = 0) is -1000, the
        // skull (d = 2) +1000, brain (d = 1.02) +20, ventricles 0, the small features +40.
        for (float& d : v.data) d = std::round(1000.0f * (d - 1.0f));
        v.background = -1000.0f;
        v.backgroundSource = "synthetic CT in HU (air)";
    }
    v.source = "synthetic:" + name + ":" + std::to_string(n);
    return v;
}

}  // namespace splat
