// ParaView's colour-map presets ("Save preset" / "Export" in ParaView's colour map editor):
// a JSON array of objects
//   {"Name": "...", "ColorSpace": "RGB"|"HSV"|"Lab"|"Diverging", "RGBPoints": [x, r, g, b, ...],
//    "Points": [x, opacity, midpoint, sharpness, ...], "NanColor": [...], ...}
// turned into the project's piecewise-linear RGBA function. The x are absolute data values
// (ParaView rescales a preset to the data range only when told to: --tf-rescale). Colours
// interpolated in a space other than RGB, and opacity segments with a midpoint other than 0.5
// or a sharpness other than 0, are resampled at kPieces pieces per interval (the curve of
// VTK's vtkPiecewiseFunction; Moreland's diverging Msh interpolation; D65 CIELAB).
#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "splat/error.h"
#include "splat/transfer.h"

namespace splat {

namespace {

constexpr int kPieces = 32;  // resampling of non-linear intervals
using Rgb = std::array<double, 3>;

enum class Space { Rgb, Hsv, Lab, Diverging };

// ---- colour spaces (sRGB primaries, D65 white) ------------------------------------------
double toLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }
double fromLinear(double c) {
    c = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return std::clamp(c, 0.0, 1.0);
}
constexpr Rgb kWhite{0.9505, 1.0, 1.089};
double labF(double t) { return t > 0.008856 ? std::cbrt(t) : 7.787 * t + 16.0 / 116.0; }
double labFInv(double f) { return f > 0.20689 ? f * f * f : (f - 16.0 / 116.0) / 7.787; }

Rgb rgbToLab(const Rgb& c) {
    const double r = toLinear(c[0]), g = toLinear(c[1]), b = toLinear(c[2]);
    const double x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / kWhite[0];
    const double y = (0.2126 * r + 0.7152 * g + 0.0722 * b) / kWhite[1];
    const double z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / kWhite[2];
    const double fx = labF(x), fy = labF(y), fz = labF(z);
    return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}
Rgb labToRgb(const Rgb& lab) {
    const double fy = (lab[0] + 16.0) / 116.0, fx = fy + lab[1] / 500.0, fz = fy - lab[2] / 200.0;
    const double x = labFInv(fx) * kWhite[0], y = labFInv(fy) * kWhite[1],
                 z = labFInv(fz) * kWhite[2];
    return {fromLinear(3.2406 * x - 1.5372 * y - 0.4986 * z),
            fromLinear(-0.9689 * x + 1.8758 * y + 0.0415 * z),
            fromLinear(0.0557 * x - 0.2040 * y + 1.0570 * z)};
}

Rgb rgbToHsv(const Rgb& c) {
    const double mx = std::max({c[0], c[1], c[2]}), mn = std::min({c[0], c[1], c[2]});
    const double d = mx - mn;
    double h = 0;
    if (d > 0) {
        if (mx == c[0])
            h = (c[1] - c[2]) / d;
        else if (mx == c[1])
            h = 2.0 + (c[2] - c[0]) / d;
        else
            h = 4.0 + (c[0] - c[1]) / d;
        h /= 6.0;
        if (h < 0) h += 1.0;
    }
    return {h, mx > 0 ? d / mx : 0.0, mx};
}
Rgb hsvToRgb(const Rgb& c) {
    const double h = (c[0] - std::floor(c[0])) * 6.0, s = c[1], v = c[2];
    const int i = std::min(int(h), 5);
    const double f = h - i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    switch (i) {
        case 0:
            return {v, t, p};
        case 1:
            return {q, v, p};
        case 2:
            return {p, v, t};
        case 3:
            return {p, q, v};
        case 4:
            return {t, p, v};
        default:
            return {v, p, q};
    }
}

// Moreland, "Diverging Color Maps for Scientific Visualization" (2009): Msh coordinates.
Rgb labToMsh(const Rgb& lab) {
    const double m = std::sqrt(lab[0] * lab[0] + lab[1] * lab[1] + lab[2] * lab[2]);
    const double s = m > 0.001 ? std::acos(std::clamp(lab[0] / m, -1.0, 1.0)) : 0.0;
    const double h = s > 0.001 ? std::atan2(lab[2], lab[1]) : 0.0;
    return {m, s, h};
}
Rgb mshToLab(const Rgb& msh) {
    return {msh[0] * std::cos(msh[1]), msh[0] * std::sin(msh[1]) * std::cos(msh[2]),
            msh[0] * std::sin(msh[1]) * std::sin(msh[2])};
}
// Hue of a saturated colour spun towards an unsaturated one of magnitude mUnsat.
double adjustHue(const Rgb& msh, double mUnsat) {
    if (msh[0] >= mUnsat - 0.1) return msh[2];
    const double spin =
        msh[1] * std::sqrt(mUnsat * mUnsat - msh[0] * msh[0]) / (msh[0] * std::sin(msh[1]));
    return msh[2] > -M_PI / 3 ? msh[2] + spin : msh[2] - spin;
}
Rgb divergingMix(const Rgb& c1, const Rgb& c2, double s) {
    Rgb a = labToMsh(rgbToLab(c1)), b = labToMsh(rgbToLab(c2));
    double hueGap = std::abs(a[2] - b[2]);
    if (hueGap > M_PI) hueGap = 2 * M_PI - hueGap;
    if (a[1] > 0.05 && b[1] > 0.05 && hueGap > M_PI / 3) {
        // Two distinct saturated colours: through white at the middle.
        const double mid = std::max({a[0], b[0], 88.0});
        if (s < 0.5) {
            b = {mid, 0.0, 0.0};
            s *= 2.0;
        } else {
            a = {mid, 0.0, 0.0};
            s = 2.0 * s - 1.0;
        }
    }
    if (a[1] < 0.05 && b[1] > 0.05)
        a[2] = adjustHue(b, a[0]);
    else if (b[1] < 0.05 && a[1] > 0.05)
        b[2] = adjustHue(a, b[0]);
    Rgb m;
    for (int c = 0; c < 3; ++c) m[c] = (1 - s) * a[c] + s * b[c];
    return labToRgb(mshToLab(m));
}

Rgb mix(Space space, const Rgb& a, const Rgb& b, double s) {
    Rgb out;
    switch (space) {
        case Space::Rgb:
            for (int c = 0; c < 3; ++c) out[c] = (1 - s) * a[c] + s * b[c];
            return out;
        case Space::Hsv: {
            Rgb ha = rgbToHsv(a), hb = rgbToHsv(b);
            if (hb[0] - ha[0] > 0.5) ha[0] += 1.0;  // the shorter way round (VTK's HSVWrap)
            if (ha[0] - hb[0] > 0.5) hb[0] += 1.0;
            for (int c = 0; c < 3; ++c) out[c] = (1 - s) * ha[c] + s * hb[c];
            return hsvToRgb(out);
        }
        case Space::Lab: {
            const Rgb la = rgbToLab(a), lb = rgbToLab(b);
            for (int c = 0; c < 3; ++c) out[c] = (1 - s) * la[c] + s * lb[c];
            return labToRgb(out);
        }
        default:
            return divergingMix(a, b, s);
    }
}

// vtkPiecewiseFunction's segment curve: position s in [0, 1] warped by the midpoint, then a
// Hermite curve whose slopes and compression follow the sharpness.
double opacityCurve(double s, double y1, double y2, double midpoint, double sharpness) {
    midpoint = std::clamp(midpoint, 1e-5, 1.0 - 1e-5);
    s = s < midpoint ? 0.5 * s / midpoint : 0.5 + 0.5 * (s - midpoint) / (1.0 - midpoint);
    if (sharpness > 0.99) return s < 0.5 ? y1 : y2;
    if (sharpness < 0.01) return (1 - s) * y1 + s * y2;
    if (s < 0.5)
        s = 0.5 * std::pow(2 * s, 1.0 + 10 * sharpness);
    else if (s > 0.5)
        s = 1.0 - 0.5 * std::pow(2 * (1 - s), 1.0 + 10 * sharpness);
    const double ss = s * s, sss = ss * s;
    const double h1 = 2 * sss - 3 * ss + 1, h2 = -2 * sss + 3 * ss, h3 = sss - 2 * ss + s,
                 h4 = sss - ss;
    const double t = (1.0 - sharpness) * (y2 - y1);
    const double v = h1 * y1 + h2 * y2 + h3 * t + h4 * t;
    return std::clamp(v, std::min(y1, y2), std::max(y1, y2));
}

// Nodes of one ParaView function: positions and values (3 colour channels, or opacity with
// its midpoint and sharpness).
struct Nodes {
    std::vector<double> x;
    std::vector<std::array<double, 3>> v;
    bool colour = true;
    Space space = Space::Rgb;

    bool linear(std::size_t seg) const {
        if (colour) return space == Space::Rgb;
        return v[seg][1] == 0.5 && v[seg][2] == 0.0;
    }
    Rgb between(std::size_t a, double at) const {
        const double s = (at - x[a]) / (x[a + 1] - x[a]);
        if (colour) return mix(space, v[a], v[a + 1], s);
        return {opacityCurve(s, v[a][0], v[a + 1][0], v[a][1], v[a][2]), 0, 0};
    }
    /// The value at `at`, as the limit from the left or the right (steps: equal x twice).
    Rgb at(double at, bool fromLeft) const {
        const std::size_t n = x.size();
        if (at < x.front() || n == 1) return v.front();
        if (at > x.back()) return v.back();
        if (fromLeft) {
            std::size_t i = std::size_t(std::lower_bound(x.begin(), x.end(), at) - x.begin());
            if (i == 0) return v.front();
            return between(i - 1, at);
        }
        const std::size_t j = std::size_t(std::upper_bound(x.begin(), x.end(), at) - x.begin());
        if (j == n) return v.back();
        return between(j - 1, at);
    }
    /// Whether the function is non-linear anywhere inside (lo, hi).
    bool linearOver(double lo, double hi) const {
        for (std::size_t a = 0; a + 1 < x.size(); ++a)
            if (x[a] < hi && x[a + 1] > lo && !linear(a)) return false;
        return true;
    }
};

Nodes readNodes(const nlohmann::json& arr, int per, bool colour, const std::string& key,
                const std::string& what) {
    if (!arr.is_array() || arr.empty() || arr.size() % std::size_t(per) != 0)
        throw Error(what + ": \"" + key + "\" must hold groups of " + std::to_string(per) +
                    " numbers");
    Nodes n;
    n.colour = colour;
    for (std::size_t q = 0; q < arr.size(); q += std::size_t(per)) {
        std::array<double, 4> g{};
        for (int c = 0; c < per; ++c) {
            if (!arr[q + c].is_number()) throw Error(what + ": \"" + key + "\" holds a non-number");
            g[c] = arr[q + c].get<double>();
            if (!std::isfinite(g[c]))
                throw Error(what + ": \"" + key + "\" holds a non-finite number");
        }
        const std::size_t node = q / std::size_t(per);
        if (!n.x.empty() && g[0] < n.x.back())
            throw Error(what + ": \"" + key + "\" positions must be non-decreasing (node " +
                        std::to_string(node) + ")");
        for (int c = 1; c < (colour ? 4 : 2); ++c)
            if (!(g[c] >= 0.0 && g[c] <= 1.0))
                throw Error(what + ": \"" + key + "\" node " + std::to_string(node) +
                            (colour ? " has a colour" : " has an opacity") + " outside [0, 1]");
        if (!colour && (!(g[2] >= 0.0 && g[2] <= 1.0) || !(g[3] >= 0.0 && g[3] <= 1.0)))
            throw Error(what + ": \"" + key + "\" node " + std::to_string(node) +
                        " has a midpoint or sharpness outside [0, 1]");
        n.x.push_back(g[0]);
        n.v.push_back({g[1], g[2], g[3]});  // colour, or opacity, midpoint, sharpness
    }
    return n;
}

Space spaceOf(const std::string& s, const std::string& what) {
    if (s == "RGB") return Space::Rgb;
    if (s == "HSV") return Space::Hsv;
    if (s == "Lab" || s == "CIELAB" || s == "Lab/CIELAB") return Space::Lab;
    if (s == "Diverging") return Space::Diverging;
    throw Error(what + ": \"ColorSpace\": \"" + s +
                "\" is not supported (RGB, HSV, Lab, CIELAB, Diverging)");
}

bool isTrue(const nlohmann::json& o, const char* key) {
    if (!o.contains(key)) return false;
    const auto& v = o[key];
    return v.is_boolean() ? v.get<bool>() : (v.is_number() && v.get<double>() != 0.0);
}

TransferFunction fromPreset(const nlohmann::json& o, const std::string& what) {
    static const std::set<std::string> kKnown = {"Name",
                                                 "Creator",
                                                 "ColorSpace",
                                                 "RGBPoints",
                                                 "Points",
                                                 "NanColor",
                                                 "NanOpacity",
                                                 "DefaultMap",
                                                 "License",
                                                 "AboveRangeColor",
                                                 "BelowRangeColor",
                                                 "UseAboveRangeColor",
                                                 "UseBelowRangeColor",
                                                 "Annotations",
                                                 "IndexedColors",
                                                 "IndexedOpacities",
                                                 "AnnotatedValues",
                                                 "InterpretValuesAsCategories",
                                                 "ShowIndexedColorActiveValues",
                                                 "UseLogScale",
                                                 "AutomaticRescaleRangeMode",
                                                 "RescaleOnVisibilityChange",
                                                 "Discretize",
                                                 "NumberOfTableValues",
                                                 "HSVWrap",
                                                 "Source",
                                                 "Comment"};
    for (const auto& item : o.items())
        if (!kKnown.count(item.key()))
            throw Error(what + ": unknown ParaView preset key \"" + item.key() + "\"");
    if (isTrue(o, "InterpretValuesAsCategories"))
        throw Error(what + ": a categorical (indexed) ParaView map; use --label-colors for labels");
    if (isTrue(o, "UseLogScale"))
        throw Error(what +
                    ": \"UseLogScale\" maps are not supported (the transfer function is "
                    "linear in the data value)");
    if (!o.contains("RGBPoints")) throw Error(what + ": missing \"RGBPoints\": [x, r, g, b, ...]");
    Nodes colour = readNodes(o["RGBPoints"], 4, true, "RGBPoints", what);
    if (o.contains("ColorSpace")) {
        if (!o["ColorSpace"].is_string()) throw Error(what + ": \"ColorSpace\" must be a string");
        colour.space = spaceOf(o["ColorSpace"].get<std::string>(), what);
    }
    Nodes opacity;
    if (o.contains("Points")) {
        opacity = readNodes(o["Points"], 4, false, "Points", what);
    } else {
        // ParaView's default scalar opacity: a line from 0 to 1 over the colour map's range.
        opacity.colour = false;
        opacity.x = {colour.x.front(), colour.x.back()};
        opacity.v = {{0.0, 0.5, 0.0}, {1.0, 0.5, 0.0}};
    }

    TransferFunction tf;
    tf.name = o.contains("Name") && o["Name"].is_string() ? o["Name"].get<std::string>() : what;
    tf.normalized = false;
    tf.unitDistance = 1.0;
    std::vector<double> xs = colour.x;
    xs.insert(xs.end(), opacity.x.begin(), opacity.x.end());
    std::sort(xs.begin(), xs.end());
    xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
    auto rgbaAt = [&](double x, bool fromLeft) {
        const Rgb c = colour.at(x, fromLeft);
        return glm::vec4(float(c[0]), float(c[1]), float(c[2]), float(opacity.at(x, fromLeft)[0]));
    };
    auto push = [&](double x, const glm::vec4& c) {
        if (!tf.points.empty() && tf.points.back().value == float(x) && tf.points.back().rgba == c)
            return;
        tf.points.push_back({float(x), c});
    };
    for (std::size_t q = 0; q < xs.size(); ++q) {
        push(xs[q], rgbaAt(xs[q], true));
        push(xs[q], rgbaAt(xs[q], false));  // a step: the same x twice
        if (q + 1 == xs.size()) break;
        const double lo = xs[q], hi = xs[q + 1];
        if (colour.linearOver(lo, hi) && opacity.linearOver(lo, hi)) continue;
        for (int k = 1; k < kPieces; ++k) {
            const double x = lo + (hi - lo) * k / kPieces;
            push(x, rgbaAt(x, true));
        }
    }
    tf.validate(what);
    return tf;
}

}  // namespace

TransferFunction TransferFunction::fromParaView(const std::string& text, const std::string& what,
                                                const std::string& presetName) {
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const std::exception& e) {
        throw Error(what + ": not valid JSON (" + std::string(e.what()) + ")");
    }
    if (j.is_object()) j = nlohmann::json::array({j});
    if (!j.is_array() || j.empty())
        throw Error(what + ": a ParaView preset file is a non-empty array of colour maps");
    std::string names;
    for (const auto& o : j) {
        if (!o.is_object()) throw Error(what + ": every ParaView preset must be a JSON object");
        const std::string name =
            o.contains("Name") && o["Name"].is_string() ? o["Name"].get<std::string>() : "";
        names += (names.empty() ? "" : ", ") + name;
        if (presetName.empty() ? j.size() == 1 : name == presetName) {
            try {
                return fromPreset(o, what + (presetName.empty() ? "" : "#" + presetName));
            } catch (const nlohmann::json::exception& e) {
                throw Error(what + ": bad ParaView preset (" + std::string(e.what()) + ")");
            }
        }
    }
    if (presetName.empty())
        throw Error(what + " holds " + std::to_string(j.size()) +
                    " ParaView presets; pick one with FILE.json#Name (" + names + ")");
    throw Error(what + ": no ParaView preset named '" + presetName + "' (" + names + ")");
}

}  // namespace splat
