// LDR-FLIP, written from the paper (Andersson et al., "FLIP: A Difference Evaluator for
// Alternating Images", HPG 2020; see splat/flip.h) and the authors' public note "A Note on
// the Separability of the Filters Used in FLIP" (Andersson 2022), which gives the separable
// form of the paper's two-dimensional filters used here.
//
// Pipeline, per image pair (the paper's Sec. "Algorithm"):
//   colour:  linear RGB -> XYZ -> YCxCz; CSF filtering per channel; back to linear RGB,
//            clamped; CIELAB; Hunt adjustment; HyAB distance; remapping to [0, 1] = ΔEc.
//   feature: luminance Y/Yn of the unfiltered images; edges (first Gaussian derivatives) and
//            points (second derivatives); difference of the magnitudes -> ΔEf.
//   result:  ΔE = ΔEc^(1 - ΔEf).
//
// Numerics: per-pixel colour transforms in double, images and convolutions in float (as the
// authors' tools). Every pixel is computed by the same sequence of operations whatever the
// thread count (rows are independent), and means are summed serially in double, so results
// do not depend on the number of threads.
#include "splat/flip.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "analysis/flip_image.h"
#include "splat/error.h"

namespace splat {
namespace {

using std::numbers::pi;

// ---- Parameters from the paper ------------------------------------------------------------

// Contrast sensitivity functions (CSFs) as sums of two Gaussians in frequency,
// S(f) = a1 e^(-b1 f^2) + a2 e^(-b2 f^2) (f in cycles per degree), per opponent channel
// (paper, spatial filtering; parameters from its table of CSF parameters).
struct Csf {
    double a1, b1, a2, b2;
};
constexpr Csf kCsfAchromatic{1.0, 0.0047, 0.0, 1e-5};
constexpr Csf kCsfRedGreen{1.0, 0.0053, 0.0, 1e-5};
constexpr Csf kCsfBlueYellow{34.1, 0.04, 13.5, 0.025};
constexpr double kCsfMaxB = 0.04;  // the largest b of the three: it sets the filter radius

// Colour difference remapping: ΔE_HyAB^qc, then a piecewise-linear map taking pc * cmax to pt
// and cmax (the distance between green and blue) to 1 (paper, colour metric).
constexpr double kQc = 0.7, kPc = 0.4, kPt = 0.95;

// Feature detection: w = 0.082 degrees is the peak-to-trough width of the edge detector, whose
// Gaussian has standard deviation 0.5 w (in degrees). Feature differences are raised to qf.
constexpr double kFeatureWidth = 0.082, kQf = 0.5;

// ---- Colour spaces ------------------------------------------------------------------------

using Mat3 = std::array<std::array<double, 3>, 3>;

// Linear sRGB to CIE XYZ: derived (exactly, in rationals) from the sRGB primaries' and D65
// white's chromaticities (IEC 61966-2-1), so RGB (1, 1, 1) maps to the white point.
constexpr Mat3 kRgbToXyz{{{506752.0 / 1228815.0, 87881.0 / 245763.0, 12673.0 / 70218.0},
                          {87098.0 / 409605.0, 175762.0 / 245763.0, 12673.0 / 175545.0},
                          {7918.0 / 409605.0, 87881.0 / 737289.0, 1001167.0 / 1053270.0}}};

constexpr Mat3 inverse(const Mat3& m) {
    const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    const double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    const double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    const double invDet = 1.0 / (m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02);
    return {{{c00 * invDet, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * invDet,
              (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * invDet},
             {c01 * invDet, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * invDet,
              (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * invDet},
             {c02 * invDet, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * invDet,
              (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * invDet}}};
}
constexpr Mat3 kXyzToRgb = inverse(kRgbToXyz);

struct Vec3d {
    double x, y, z;
};

constexpr Vec3d mul(const Mat3& m, const Vec3d& v) {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

// Reference white (D65): XYZ of linear RGB (1, 1, 1).
constexpr Vec3d kWhite = mul(kRgbToXyz, {1.0, 1.0, 1.0});

// YCxCz, the linearised CIELAB of Johnson and Fairchild that FLIP filters in:
// Yy = 116 Y/Yn - 16, Cx = 500 (X/Xn - Y/Yn), Cz = 200 (Y/Yn - Z/Zn).
Vec3d xyzToYcxcz(const Vec3d& c) {
    const double x = c.x / kWhite.x, y = c.y / kWhite.y, z = c.z / kWhite.z;
    return {116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)};
}

Vec3d ycxczToXyz(const Vec3d& c) {
    const double y = (c.x + 16.0) / 116.0;
    return {(c.y / 500.0 + y) * kWhite.x, y * kWhite.y, (y - c.z / 200.0) * kWhite.z};
}

// CIE 1976 L*a*b* relative to the same white.
double labF(double t) {
    constexpr double delta = 6.0 / 29.0;
    return t > delta * delta * delta ? std::cbrt(t) : t / (3.0 * delta * delta) + 4.0 / 29.0;
}

Vec3d xyzToLab(const Vec3d& c) {
    const double fx = labF(c.x / kWhite.x), fy = labF(c.y / kWhite.y), fz = labF(c.z / kWhite.z);
    return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

// Hunt effect (colourfulness grows with luminance): a' = 0.01 L a, b' = 0.01 L b.
Vec3d huntAdjust(const Vec3d& lab) { return {lab.x, 0.01 * lab.x * lab.y, 0.01 * lab.x * lab.z}; }

// Colour as compared: linear RGB clamped to [0, 1] -> CIELAB -> Hunt-adjusted.
Vec3d huntLab(const Vec3d& rgb) {
    const Vec3d c{std::clamp(rgb.x, 0.0, 1.0), std::clamp(rgb.y, 0.0, 1.0),
                  std::clamp(rgb.z, 0.0, 1.0)};
    return huntAdjust(xyzToLab(mul(kRgbToXyz, c)));
}

// HyAB distance (Abasi et al.): city-block in lightness, Euclidean in the chromatic plane.
double hyab(const Vec3d& p, const Vec3d& q) {
    const double da = p.y - q.y, db = p.z - q.z;
    return std::abs(p.x - q.x) + std::sqrt(da * da + db * db);
}

// Maps a raised HyAB distance (ΔE_HyAB^qc) to ΔEc in [0, 1]: the lower part, below
// pc * cmax, is compressed linearly onto [0, pt] and the rest onto [pt, 1]. Green and blue
// are the most distant colours of the gamut (checked on a 9^3 grid of the RGB cube), so the
// final clamp only catches rounding.
struct ColourRemap {
    double cmax = 0;

    ColourRemap() {
        cmax = std::pow(hyab(huntLab({0.0, 1.0, 0.0}), huntLab({0.0, 0.0, 1.0})), kQc);
    }
    double operator()(double raised) const {
        const double knee = kPc * cmax;
        const double e = raised < knee ? kPt / knee * raised
                                       : kPt + (raised - knee) / (cmax - knee) * (1.0 - kPt);
        return std::min(e, 1.0);
    }
};

// Channel value as FLIP takes it: clamped to [0, 1], NaN as 0.
double unit(float v) { return v > 0.0f ? (v < 1.0f ? double(v) : 1.0) : 0.0; }

double srgbDecode(double e) {
    return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
}

// ---- Planes and separable filtering -------------------------------------------------------

/// A float image plane, row-major, row 0 on top; not initialised.
struct Plane {
    int width = 0, height = 0;
    std::unique_ptr<float[]> v;

    Plane(int w, int h) : width(w), height(h), v(new float[std::size_t(w) * std::size_t(h)]) {}
    float* row(int y) { return v.get() + std::size_t(y) * width; }
    const float* row(int y) const { return v.get() + std::size_t(y) * width; }
};

/// A one-dimensional kernel, symmetric or antisymmetric about its centre, stored as the
/// weights at offsets 0..radius. Applying it pairwise, (p[-t] + p[+t]) or (p[-t] - p[+t]),
/// makes mirroring an image mirror the result exactly, and lets the derivative kernels,
/// whose weights sum to zero, give exactly zero on uniform regions (rounding there would be
/// magnified by the feature exponent qf).
struct Kernel {
    enum Symmetry {
        Even,         ///< weight half[t] at -t and +t
        Odd,          ///< weight half[t] at -t, -half[t] at +t (half[0] = 0)
        EvenZeroSum,  ///< weight half[t] at -t and +t, centre weight -2 sum(half[1..])
    };
    Symmetry symmetry = Even;
    std::vector<float> half;
    int radius() const { return int(half.size()) - 1; }
};

// dst[x] = sum over offsets i of weight(i) * sample(x + i), for x in [0, n), where
// at(i)[x] is sample(x + i). Along rows at(i) is the padded row shifted by i; along columns
// it is row y + i.
template <class At>
void correlate(const Kernel& k, int n, const At& at, float* dst) {
    const float* c = at(0);
    if (k.symmetry == Kernel::Even)
        for (int x = 0; x < n; ++x) dst[x] = k.half[0] * c[x];
    else
        std::fill(dst, dst + n, 0.0f);
    for (int t = 1; t <= k.radius(); ++t) {
        const float wt = k.half[t];
        const float *a = at(-t), *b = at(t);
        switch (k.symmetry) {
            case Kernel::Even:
                for (int x = 0; x < n; ++x) dst[x] += wt * (a[x] + b[x]);
                break;
            case Kernel::Odd:
                for (int x = 0; x < n; ++x) dst[x] += wt * (a[x] - b[x]);
                break;
            case Kernel::EvenZeroSum:
                for (int x = 0; x < n; ++x) dst[x] += wt * ((a[x] - c[x]) + (b[x] - c[x]));
                break;
        }
    }
}

struct NoScratch {};

// Runs body(y, scratch) for every row, rows split among threads; scratch is per task.
template <class Scratch = NoScratch, class Body>
void forRows(int height, const Body& body) {
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
        Scratch scratch;
        for (int y = r.begin(); y != r.end(); ++y) body(y, scratch);
    });
}

// Column correlation of `in` for output row y; the image is extended by repeating its border.
void correlateColumn(const Kernel& k, const Plane& in, int y, float* dst) {
    const int h = in.height;
    correlate(
        k, in.width, [&](int i) { return in.row(std::clamp(y + i, 0, h - 1)); }, dst);
}

// ---- Colour pipeline: contrast sensitivity filters ----------------------------------------

// The CSF's spatial-domain filter, s(x) = a1 sqrt(pi/b1) e^(-pi^2 x^2 / b1) + (same, a2, b2),
// x in degrees, sampled at pixel spacing 1/ppd within radius ceil(3 sqrt(b_max / (2 pi^2)) ppd)
// and normalised to unit sum. Each Gaussian term is separable, a (x, y) = g(x) g(y); with
// M^2 the two-dimensional sum of both terms, the 1-D factors g/M give the normalised filter
// (separability note, Sec. 1). Terms with a = 0 are dropped.
std::vector<Kernel> csfKernels(const Csf& csf, double ppd) {
    const int radius = int(std::ceil(3.0 * std::sqrt(kCsfMaxB / (2.0 * pi * pi)) * ppd));
    std::vector<std::vector<double>> factors;
    double sum2d = 0;
    for (const auto& [a, b] : {std::pair{csf.a1, csf.b1}, std::pair{csf.a2, csf.b2}}) {
        if (a == 0.0) continue;
        std::vector<double> g;
        double sum = 0;
        for (int t = 0; t <= radius; ++t) {
            const double x = t / ppd;
            g.push_back(std::sqrt(a * std::sqrt(pi / b)) * std::exp(-pi * pi * x * x / b));
            sum += t == 0 ? g.back() : 2.0 * g.back();
        }
        sum2d += sum * sum;
        factors.push_back(std::move(g));
    }
    const double m = std::sqrt(sum2d);
    std::vector<Kernel> kernels;
    for (const auto& g : factors) {
        Kernel k{Kernel::Even, {}};
        for (double v : g) k.half.push_back(float(v / m));
        kernels.push_back(std::move(k));
    }
    return kernels;
}

// ---- Feature pipeline: edge and point detectors -------------------------------------------

// Gaussian g (std sigma = 0.5 w ppd pixels, radius ceil(3 sigma)) and its first and second
// derivatives, -x g and (x^2/sigma^2 - 1) g (the common 1/sigma^2 cancels in normalisation).
// g is normalised to unit sum; each derivative so that its positive weights sum to 1 and its
// negative weights to -1, which makes the two-dimensional products g'(x) g(y) and g''(x) g(y)
// normalised the same way (separability note, Sec. 2).
struct FeatureKernels {
    Kernel gauss, first, second;
};

FeatureKernels featureKernels(double ppd) {
    const double sigma = 0.5 * kFeatureWidth * ppd;
    const int radius = int(std::ceil(3.0 * sigma));
    std::vector<double> g, g1, g2;  // at offsets 0..radius
    double sum = 0, positive1 = 0, positive2 = 0, negative2 = 0;
    for (int t = 0; t <= radius; ++t) {
        const double count = t == 0 ? 1.0 : 2.0;  // offsets -t and +t
        g.push_back(std::exp(-double(t) * t / (2.0 * sigma * sigma)));
        g1.push_back(t * g.back());  // -x g at x = -t, the positive side
        g2.push_back((double(t) * t / (sigma * sigma) - 1.0) * g.back());
        sum += count * g.back();
        positive1 += g1.back();
        (g2.back() > 0 ? positive2 : negative2) += count * g2.back();
    }
    FeatureKernels f{{Kernel::Even, {}}, {Kernel::Odd, {}}, {Kernel::EvenZeroSum, {}}};
    for (int t = 0; t <= radius; ++t) {
        f.gauss.half.push_back(float(g[t] / sum));
        // At tiny ppd the Gaussian can vanish on the grid beyond the centre: no edges then.
        f.first.half.push_back(positive1 > 0 ? float(g1[t] / positive1) : 0.0f);
        f.second.half.push_back(float(g2[t] > 0 ? g2[t] / positive2 : -g2[t] / negative2));
    }
    return f;
}

// ---- One image, as FLIP perceives it ------------------------------------------------------

struct Filters {
    std::array<std::vector<Kernel>, 3> csf;  // per opponent channel Yy, Cx, Cz; one per term
    FeatureKernels feature;
    int padding = 0;  // the largest radius

    explicit Filters(double ppd)
        : csf{csfKernels(kCsfAchromatic, ppd), csfKernels(kCsfRedGreen, ppd),
              csfKernels(kCsfBlueYellow, ppd)},
          feature(featureKernels(ppd)) {
        for (const auto& kernels : csf)
            for (const Kernel& k : kernels) padding = std::max(padding, k.radius());
        padding = std::max(padding, feature.gauss.radius());
    }
};

/// What the comparison needs of one image: its CSF-filtered colour in Hunt-adjusted CIELAB,
/// and the magnitudes of its edge and point responses.
struct Perceived {
    std::array<Plane, 3> lab;
    Plane edge, point;
};

/// Intermediate planes of the separable filters (the row pass), reused for both images.
struct RowPassed {
    std::vector<Plane> csf;       // per CSF kernel, in Filters::csf order
    Plane smooth, first, second;  // luminance * g, g', g'' along rows

    RowPassed(const Filters& f, int w, int h) : smooth(w, h), first(w, h), second(w, h) {
        for (const auto& kernels : f.csf)
            for (std::size_t k = 0; k < kernels.size(); ++k) csf.emplace_back(w, h);
    }
};

// Row pass: converts each row (extended by repeating its border pixels) to YCxCz and to the
// luminance Y/Yn of the feature pipeline (paper: the achromatic channel normalised to [0, 1],
// (Yy + 16) / 116), and correlates it with every row kernel.
void rowPass(const Image& im, const Filters& f, RowPassed& out) {
    const int w = im.width, pad = f.padding, n = w + 2 * pad;
    struct Rows {
        std::array<std::vector<float>, 4> channel;  // Yy, Cx, Cz, luminance
    };
    forRows<Rows>(im.height, [&](int y, Rows& rows) {
        for (auto& c : rows.channel) c.resize(std::size_t(n));
        for (int i = 0; i < n; ++i) {
            const glm::vec4& p = im.at(std::clamp(i - pad, 0, w - 1), y);
            const Vec3d xyz = mul(kRgbToXyz, {unit(p.r), unit(p.g), unit(p.b)});
            const Vec3d c = xyzToYcxcz(xyz);
            rows.channel[0][i] = float(c.x);
            rows.channel[1][i] = float(c.y);
            rows.channel[2][i] = float(c.z);
            rows.channel[3][i] = float(xyz.y / kWhite.y);
        }
        const auto along = [&](int c) {
            const float* centre = rows.channel[c].data() + pad;
            return [centre](int i) { return centre + i; };
        };
        std::size_t plane = 0;
        for (int c = 0; c < 3; ++c)
            for (const Kernel& k : f.csf[c]) correlate(k, w, along(c), out.csf[plane++].row(y));
        correlate(f.feature.gauss, w, along(3), out.smooth.row(y));
        correlate(f.feature.first, w, along(3), out.first.row(y));
        correlate(f.feature.second, w, along(3), out.second.row(y));
    });
}

// Column pass of the CSF filters, then back to linear RGB, clamped to [0, 1] (paper: colours
// outside the gamut after filtering), CIELAB and the Hunt adjustment.
void colourColumnPass(const RowPassed& rows, const Filters& f, Perceived& out) {
    const int w = out.edge.width;
    struct Rows {
        std::array<std::vector<float>, 3> channel;
        std::vector<float> term;
    };
    forRows<Rows>(out.edge.height, [&](int y, Rows& r) {
        std::size_t plane = 0;
        r.term.resize(std::size_t(w));
        for (int c = 0; c < 3; ++c) {
            r.channel[c].resize(std::size_t(w));
            for (std::size_t k = 0; k < f.csf[c].size(); ++k, ++plane) {
                float* dst = k == 0 ? r.channel[c].data() : r.term.data();
                correlateColumn(f.csf[c][k], rows.csf[plane], y, dst);
                if (k > 0)
                    for (int x = 0; x < w; ++x) r.channel[c][x] += r.term[x];
            }
        }
        float *L = out.lab[0].row(y), *A = out.lab[1].row(y), *B = out.lab[2].row(y);
        for (int x = 0; x < w; ++x) {
            const Vec3d xyz = ycxczToXyz({r.channel[0][x], r.channel[1][x], r.channel[2][x]});
            const Vec3d lab = huntLab(mul(kXyzToRgb, xyz));
            L[x] = float(lab.x);
            A[x] = float(lab.y);
            B[x] = float(lab.z);
        }
    });
}

// Column pass of the feature filters: the edge response is (g'(x) g(y), g(x) g'(y)) * Y, the
// point response (g''(x) g(y), g(x) g''(y)) * Y; their magnitudes are kept.
void featureColumnPass(const RowPassed& rows, const Filters& f, Perceived& out) {
    const int w = out.edge.width;
    struct Rows {
        std::vector<float> ex, ey, px, py;
    };
    forRows<Rows>(out.edge.height, [&](int y, Rows& r) {
        for (auto* v : {&r.ex, &r.ey, &r.px, &r.py}) v->resize(std::size_t(w));
        correlateColumn(f.feature.gauss, rows.first, y, r.ex.data());
        correlateColumn(f.feature.first, rows.smooth, y, r.ey.data());
        correlateColumn(f.feature.gauss, rows.second, y, r.px.data());
        correlateColumn(f.feature.second, rows.smooth, y, r.py.data());
        float *edge = out.edge.row(y), *point = out.point.row(y);
        for (int x = 0; x < w; ++x) {
            edge[x] = std::sqrt(r.ex[x] * r.ex[x] + r.ey[x] * r.ey[x]);
            point[x] = std::sqrt(r.px[x] * r.px[x] + r.py[x] * r.py[x]);
        }
    });
}

Perceived perceive(const Image& im, const Filters& f, RowPassed& scratch) {
    const int w = im.width, h = im.height;
    Perceived p{{Plane(w, h), Plane(w, h), Plane(w, h)}, Plane(w, h), Plane(w, h)};
    rowPass(im, f, scratch);
    colourColumnPass(scratch, f, p);
    featureColumnPass(scratch, f, p);
    return p;
}

// ---- Entry points -------------------------------------------------------------------------

void checkInputs(const Image& test, const Image& reference, const FlipOptions& options) {
    if (test.width != reference.width || test.height != reference.height)
        throw Error("flip: image sizes differ (" + std::to_string(test.width) + "x" +
                    std::to_string(test.height) + " vs reference " +
                    std::to_string(reference.width) + "x" + std::to_string(reference.height) + ")");
    if (test.width <= 0 || test.height <= 0) throw Error("flip: empty images");
    const std::size_t count = std::size_t(test.width) * std::size_t(test.height);
    if (test.pixels.size() != count || reference.pixels.size() != count)
        throw Error("flip: malformed image (pixel count does not match its size)");
    const double ppd = options.pixelsPerDegree;
    if (!std::isfinite(ppd) || ppd <= 0.0 || ppd > 1e5)
        throw Error("flip: pixelsPerDegree must be in (0, 1e5], got " + std::to_string(ppd));
}

// Serial, so the same for any thread count.
double meanOf(const std::vector<float>& map) {
    double sum = 0;
    for (float v : map) sum += v;
    return sum / double(map.size());
}

Image srgbDecoded(const Image& im) {
    Image out = im;
    for (glm::vec4& p : out.pixels)
        for (int c = 0; c < 3; ++c) p[c] = float(srgbDecode(unit(p[c])));
    return out;
}

// Per pixel ΔE of two perceived images of the same size.
std::vector<float> errorMap(const Perceived& t, const Perceived& r) {
    const int w = t.edge.width, h = t.edge.height;
    static const ColourRemap remap;
    std::vector<float> map(std::size_t(w) * std::size_t(h));
    forRows(h, [&](int y, NoScratch&) {
        const float *tl = t.lab[0].row(y), *ta = t.lab[1].row(y), *tb = t.lab[2].row(y);
        const float *rl = r.lab[0].row(y), *ra = r.lab[1].row(y), *rb = r.lab[2].row(y);
        const float *te = t.edge.row(y), *tp = t.point.row(y);
        const float *re = r.edge.row(y), *rp = r.point.row(y);
        float* out = map.data() + std::size_t(y) * w;
        for (int x = 0; x < w; ++x) {
            // Colour difference ΔEc: HyAB distance raised to qc, remapped to [0, 1].
            const double colour =
                remap(std::pow(hyab({tl[x], ta[x], tb[x]}, {rl[x], ra[x], rb[x]}), kQc));
            // Feature difference ΔEf = (max(|edge_r - edge_t|, |point_r - point_t|) / sqrt 2)^qf.
            const double featureDiff = std::max(std::abs(te[x] - re[x]), std::abs(tp[x] - rp[x]));
            const double feature = std::min(std::pow(featureDiff / std::numbers::sqrt2, kQf), 1.0);
            // ΔE = ΔEc^(1 - ΔEf): features raise the colour difference towards 1.
            out[x] = float(std::pow(colour, 1.0 - feature));
        }
    });
    return map;
}

}  // namespace

std::vector<float> flipErrorMap(const Image& test, const Image& reference,
                                const FlipOptions& options) {
    checkInputs(test, reference, options);
    const Filters filters(options.pixelsPerDegree);
    RowPassed scratch(filters, test.width, test.height);
    return errorMap(perceive(test, filters, scratch), perceive(reference, filters, scratch));
}

double flipMean(const Image& test, const Image& reference, const FlipOptions& options) {
    return meanOf(flipErrorMap(test, reference, options));
}

std::vector<float> flipErrorMapSrgb(const Image& test, const Image& reference,
                                    const FlipOptions& options) {
    checkInputs(test, reference, options);
    return flipErrorMap(srgbDecoded(test), srgbDecoded(reference), options);
}

double flipMeanSrgb(const Image& test, const Image& reference, const FlipOptions& options) {
    return meanOf(flipErrorMapSrgb(test, reference, options));
}

namespace analysis {

struct FlipImage::Maps {
    Perceived perceived;
};

FlipImage::FlipImage(const Image& image, const FlipOptions& options)
    : width_(image.width), height_(image.height), pixelsPerDegree_(options.pixelsPerDegree) {
    checkInputs(image, image, options);
    const Filters filters(options.pixelsPerDegree);
    RowPassed scratch(filters, image.width, image.height);
    maps_ = std::make_shared<const Maps>(Maps{perceive(image, filters, scratch)});
}

std::vector<float> flipErrorMap(const FlipImage& test, const FlipImage& reference) {
    if (test.width() != reference.width() || test.height() != reference.height())
        throw Error("flip: image sizes differ (" + std::to_string(test.width()) + "x" +
                    std::to_string(test.height()) + " vs reference " +
                    std::to_string(reference.width()) + "x" + std::to_string(reference.height()) +
                    ")");
    if (test.pixelsPerDegree() != reference.pixelsPerDegree())
        throw Error("flip: the two images were perceived at different pixels per degree");
    return errorMap(test.maps().perceived, reference.maps().perceived);
}

double flipMean(const FlipImage& test, const FlipImage& reference) {
    return meanOf(flipErrorMap(test, reference));
}

}  // namespace analysis

}  // namespace splat
