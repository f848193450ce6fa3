// LDR-FLIP (see splat/flip.h), following the paper's sections:
//   3.1 colour pipeline: linear RGB -> XYZ -> YCxCz; contrast sensitivity filtering per
//       channel (sums of Gaussians in degrees of visual angle); back to linear RGB, clamp,
//       CIELAB; Hunt adjustment (a, b scaled by 0.01 L); HyAB distance; remap with
//       q_c = 0.7, p_c = 0.4, p_t = 0.95 against c_max, the distance of green to blue;
//   3.2 feature pipeline: achromatic channel, first and second derivatives of a Gaussian
//       (std 0.5 w ppd, w = 0.082 degrees) for edges and points; their difference, scaled by
//       1/sqrt(2) and raised to q_f = 0.5;
//   3.3 the final error: colour^(1 - feature).
// Convolutions extend the image by its edge pixels. Rows are processed in parallel; every
// value is computed the same way for any thread count.
#include "splat/flip.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "splat/error.h"

namespace splat {

namespace {

using Vec3 = std::array<float, 3>;
constexpr double kPi = std::numbers::pi;

// sRGB (D65) linear RGB <-> XYZ.
Vec3 rgbToXyz(const Vec3& c) {
    return {0.4124564f * c[0] + 0.3575761f * c[1] + 0.1804375f * c[2],
            0.2126729f * c[0] + 0.7151522f * c[1] + 0.0721750f * c[2],
            0.0193339f * c[0] + 0.1191920f * c[1] + 0.9503041f * c[2]};
}
Vec3 xyzToRgb(const Vec3& c) {
    return {3.2404542f * c[0] - 1.5371385f * c[1] - 0.4985314f * c[2],
            -0.9692660f * c[0] + 1.8760108f * c[1] + 0.0415560f * c[2],
            0.0556434f * c[0] - 0.2040259f * c[1] + 1.0572252f * c[2]};
}
const Vec3 kWhite = rgbToXyz({1.0f, 1.0f, 1.0f});  // the reference white of the opponent spaces

Vec3 xyzToYcxcz(const Vec3& c) {
    const float x = c[0] / kWhite[0], y = c[1] / kWhite[1], z = c[2] / kWhite[2];
    return {116.0f * y - 16.0f, 500.0f * (x - y), 200.0f * (y - z)};
}
Vec3 ycxczToXyz(const Vec3& c) {
    const float y = (c[0] + 16.0f) / 116.0f;
    return {(c[1] / 500.0f + y) * kWhite[0], y * kWhite[1], (y - c[2] / 200.0f) * kWhite[2]};
}
Vec3 xyzToLab(const Vec3& c) {
    auto f = [](float t) {
        constexpr float d = 6.0f / 29.0f;
        return t > d * d * d ? std::cbrt(t) : t / (3.0f * d * d) + 4.0f / 29.0f;
    };
    const float fx = f(c[0] / kWhite[0]), fy = f(c[1] / kWhite[1]), fz = f(c[2] / kWhite[2]);
    return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}
float srgbToLinear(float v) {
    v = std::clamp(v, 0.0f, 1.0f);
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

/// Hunt-adjusted CIELAB of a linear RGB colour.
Vec3 huntLab(const Vec3& rgb) {
    Vec3 lab = xyzToLab(rgbToXyz(rgb));
    lab[1] *= 0.01f * lab[0];
    lab[2] *= 0.01f * lab[0];
    return lab;
}
float hyab(const Vec3& a, const Vec3& b) {
    const float da = a[1] - b[1], db = a[2] - b[2];
    return std::abs(a[0] - b[0]) + std::sqrt(da * da + db * db);
}

struct Planes {  // three float planes of w x h
    int w = 0, h = 0;
    std::array<std::vector<float>, 3> c;
    Planes(int w_, int h_) : w(w_), h(h_) {
        for (auto& p : c) p.assign(std::size_t(w) * h, 0.0f);
    }
};

template <class F>
void forRows(int h, F&& f) {
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y) f(y);
    });
}

/// Separable convolution of one plane with kernels kx (along x) and ky (along y), both of
/// odd length, the image extended by its edge pixels.
std::vector<float> convolve(const std::vector<float>& in, int w, int h,
                            const std::vector<float>& kx, const std::vector<float>& ky) {
    const int rx = int(kx.size() / 2), ry = int(ky.size() / 2);
    std::vector<float> tmp(in.size()), out(in.size());
    forRows(h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            float s = 0;
            for (int k = -rx; k <= rx; ++k)
                s += kx[std::size_t(k + rx)] * in[std::size_t(y) * w + std::clamp(x + k, 0, w - 1)];
            tmp[std::size_t(y) * w + x] = s;
        }
    });
    forRows(h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            float s = 0;
            for (int k = -ry; k <= ry; ++k)
                s +=
                    ky[std::size_t(k + ry)] * tmp[std::size_t(std::clamp(y + k, 0, h - 1)) * w + x];
            out[std::size_t(y) * w + x] = s;
        }
    });
    return out;
}

/// The contrast sensitivity filter of one opponent channel: a1 sqrt(pi/b1) exp(-pi^2 x^2/b1)
/// + a2 sqrt(pi/b2) exp(-pi^2 x^2/b2), x in degrees, as separable Gaussian terms, the 2D
/// kernel normalised to sum 1.
struct CsfChannel {
    double a1, b1, a2, b2;
};
constexpr std::array<CsfChannel, 3> kCsf{{{1.0, 0.0047, 0.0, 1e-5},     // achromatic
                                          {1.0, 0.0053, 0.0, 1e-5},     // red-green
                                          {34.1, 0.04, 13.5, 0.025}}};  // blue-yellow

std::vector<float> csfFilter(const std::vector<float>& in, int w, int h, const CsfChannel& c,
                             double ppd) {
    // One radius for all channels, from the widest Gaussian (b = 0.04).
    const int r = int(std::ceil(3.0 * std::sqrt(0.04 / (2.0 * kPi * kPi)) * ppd));
    const double dx = 1.0 / ppd;
    auto gauss1d = [&](double b) {  // exp(-pi^2 x^2 / b) per axis
        std::vector<double> g(std::size_t(2 * r + 1));
        for (int k = -r; k <= r; ++k)
            g[std::size_t(k + r)] = std::exp(-kPi * kPi * (k * dx) * (k * dx) / b);
        return g;
    };
    const std::vector<double> g1 = gauss1d(c.b1), g2 = gauss1d(c.b2);
    double s1 = 0, s2 = 0;
    for (double v : g1) s1 += v;
    for (double v : g2) s2 += v;
    // 2D weights: w1 g1(x) g1(y) + w2 g2(x) g2(y), w = a sqrt(pi / b); normalised to sum 1.
    const double w1 = c.a1 * std::sqrt(kPi / c.b1), w2 = c.a2 * std::sqrt(kPi / c.b2);
    const double total = w1 * s1 * s1 + w2 * s2 * s2;
    auto kernel = [&](const std::vector<double>& g, double scale) {
        std::vector<float> k(g.size());
        for (std::size_t i = 0; i < g.size(); ++i) k[i] = float(g[i] * scale);
        return k;
    };
    // Each term as kx (x) ky with the weight split evenly between the two axes.
    std::vector<float> out =
        convolve(in, w, h, kernel(g1, std::sqrt(w1 / total)), kernel(g1, std::sqrt(w1 / total)));
    if (w2 > 0) {
        const std::vector<float> second = convolve(in, w, h, kernel(g2, std::sqrt(w2 / total)),
                                                   kernel(g2, std::sqrt(w2 / total)));
        for (std::size_t i = 0; i < out.size(); ++i) out[i] += second[i];
    }
    return out;
}

/// Feature detection filters (section 3.2): the first (edges) and second (points) derivative
/// of a Gaussian of std 0.5 w ppd along x, each normalised so that its positive weights sum
/// to 1 and its negative weights to -1; along the other axis the Gaussian itself (sum 1).
struct FeatureKernels {
    std::vector<float> gauss, edge, point;
};
FeatureKernels featureKernels(double ppd) {
    const double sd = 0.5 * 0.082 * ppd;
    const int r = int(std::ceil(3.0 * sd));
    FeatureKernels k;
    std::vector<double> g(std::size_t(2 * r + 1)), e(g.size()), p(g.size());
    double gs = 0;
    for (int i = -r; i <= r; ++i) {
        const double v = std::exp(-double(i * i) / (2.0 * sd * sd));
        g[std::size_t(i + r)] = v;
        gs += v;
    }
    for (int i = -r; i <= r; ++i) {
        const double v = g[std::size_t(i + r)] / gs;
        e[std::size_t(i + r)] = -double(i) * v;
        p[std::size_t(i + r)] = (double(i * i) / (sd * sd) - 1.0) * v;
    }
    auto normalise = [](std::vector<double>& d) {
        double pos = 0, neg = 0;
        for (double v : d) (v > 0 ? pos : neg) += v;
        std::vector<float> out(d.size());
        for (std::size_t i = 0; i < d.size(); ++i)
            out[i] = float(d[i] > 0 ? d[i] / pos : (d[i] < 0 ? d[i] / -neg : 0.0));
        return out;
    };
    k.gauss.resize(g.size());
    for (std::size_t i = 0; i < g.size(); ++i) k.gauss[i] = float(g[i] / gs);
    k.edge = normalise(e);
    k.point = normalise(p);
    return k;
}

/// Edge and point magnitudes of the achromatic channel y (in [0, 1]).
void features(const std::vector<float>& y, int w, int h, const FeatureKernels& k,
              std::vector<float>& edges, std::vector<float>& points) {
    const std::vector<float> ex = convolve(y, w, h, k.edge, k.gauss);
    const std::vector<float> ey = convolve(y, w, h, k.gauss, k.edge);
    const std::vector<float> px = convolve(y, w, h, k.point, k.gauss);
    const std::vector<float> py = convolve(y, w, h, k.gauss, k.point);
    edges.resize(y.size());
    points.resize(y.size());
    for (std::size_t i = 0; i < y.size(); ++i) {
        edges[i] = std::sqrt(ex[i] * ex[i] + ey[i] * ey[i]);
        points[i] = std::sqrt(px[i] * px[i] + py[i] * py[i]);
    }
}

std::vector<float> flipLinear(const Image& test, const Image& reference, double ppd) {
    if (test.width != reference.width || test.height != reference.height)
        throw Error("FLIP: images differ in size (" + std::to_string(test.width) + "x" +
                    std::to_string(test.height) + " and " + std::to_string(reference.width) + "x" +
                    std::to_string(reference.height) + ")");
    if (test.pixels.empty()) throw Error("FLIP: empty image");
    if (!(ppd > 0) || ppd > 1000) throw Error("FLIP: pixels per degree must be in (0, 1000]");
    const int w = test.width, h = test.height;
    const std::size_t n = test.pixels.size();
    const FeatureKernels fk = featureKernels(ppd);

    // Per image: filtered Hunt-adjusted Lab, and the achromatic channel for features.
    auto prepare = [&](const Image& im, std::vector<Vec3>& lab, std::vector<float>& achromatic) {
        Planes opp(w, h);
        achromatic.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const glm::vec4& p = im.pixels[i];
            const Vec3 c =
                xyzToYcxcz(rgbToXyz({std::clamp(std::isfinite(p.r) ? p.r : 0.0f, 0.0f, 1.0f),
                                     std::clamp(std::isfinite(p.g) ? p.g : 0.0f, 0.0f, 1.0f),
                                     std::clamp(std::isfinite(p.b) ? p.b : 0.0f, 0.0f, 1.0f)}));
            for (int ch = 0; ch < 3; ++ch) opp.c[ch][i] = c[ch];
            achromatic[i] = (c[0] + 16.0f) / 116.0f;
        }
        for (int ch = 0; ch < 3; ++ch) opp.c[ch] = csfFilter(opp.c[ch], w, h, kCsf[ch], ppd);
        lab.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            Vec3 rgb = xyzToRgb(ycxczToXyz({opp.c[0][i], opp.c[1][i], opp.c[2][i]}));
            for (float& v : rgb) v = std::clamp(v, 0.0f, 1.0f);
            lab[i] = huntLab(rgb);
        }
    };
    std::vector<Vec3> labT, labR;
    std::vector<float> yT, yR;
    prepare(test, labT, yT);
    prepare(reference, labR, yR);
    std::vector<float> edgesT, pointsT, edgesR, pointsR;
    features(yT, w, h, fk, edgesT, pointsT);
    features(yR, w, h, fk, edgesR, pointsR);

    constexpr float qc = 0.7f, pc = 0.4f, pt = 0.95f, qf = 0.5f;
    const float cmax = std::pow(hyab(huntLab({0.0f, 1.0f, 0.0f}), huntLab({0.0f, 0.0f, 1.0f})), qc);
    std::vector<float> err(n);
    for (std::size_t i = 0; i < n; ++i) {
        const float d = std::pow(hyab(labT[i], labR[i]), qc);
        const float colour = d < pc * cmax
                                 ? pt / (pc * cmax) * d
                                 : pt + (d - pc * cmax) / (cmax - pc * cmax) * (1.0f - pt);
        const float feature =
            std::pow(std::max(std::abs(edgesR[i] - edgesT[i]), std::abs(pointsR[i] - pointsT[i])) /
                         std::sqrt(2.0f),
                     qf);
        err[i] = std::pow(colour, 1.0f - feature);
    }
    return err;
}

Image decoded(const Image& srgb) {
    Image out = srgb;
    for (glm::vec4& p : out.pixels)
        for (int c = 0; c < 3; ++c) p[c] = srgbToLinear(p[c]);
    return out;
}

}  // namespace

std::vector<float> flipErrorMap(const Image& test, const Image& reference, const FlipOptions& o) {
    return flipLinear(test, reference, o.pixelsPerDegree);
}

std::vector<float> flipErrorMapSrgb(const Image& test, const Image& reference,
                                    const FlipOptions& o) {
    return flipLinear(decoded(test), decoded(reference), o.pixelsPerDegree);
}

double flipMean(const Image& test, const Image& reference, const FlipOptions& o) {
    const std::vector<float> e = flipErrorMap(test, reference, o);
    double sum = 0;
    for (float v : e) sum += v;
    return sum / double(e.size());
}

}  // namespace splat
