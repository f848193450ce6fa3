// Piecewise-linear transfer functions, presets, JSON files and opacity correction.
#include "splat/transfer.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "splat/error.h"
#include "splat/settings.h"

namespace splat {

namespace {

TransferPoint pt(float v, float r, float g, float b, float a) { return {v, {r, g, b, a}}; }

// Presets live on the normalized domain [0, 1] = the volume's [min, max]. Opacities are
// per millimetre (unit distance 1): small numbers, because a ray crosses hundreds of them.
TransferFunction makePreset(const std::string& name) {
    TransferFunction tf;
    tf.name = name;
    tf.normalized = true;
    if (name == "gray-ramp") {
        tf.points = {pt(0.0f, 0, 0, 0, 0), pt(0.1f, 0.1f, 0.1f, 0.1f, 0), pt(1.0f, 1, 1, 1, 0.08f)};
    } else if (name == "ct-bone") {
        tf.points = {pt(0.0f, 0, 0, 0, 0), pt(0.55f, 0.8f, 0.6f, 0.45f, 0),
                     pt(0.62f, 0.95f, 0.85f, 0.7f, 0.6f), pt(1.0f, 1, 1, 0.95f, 0.9f)};
    } else if (name == "ct-soft") {
        tf.points = {pt(0.0f, 0, 0, 0, 0),
                     pt(0.12f, 0.8f, 0.4f, 0.3f, 0),
                     pt(0.3f, 0.9f, 0.5f, 0.4f, 0.02f),
                     pt(0.5f, 0.9f, 0.55f, 0.45f, 0.04f),
                     pt(0.6f, 1, 0.95f, 0.85f, 0.5f),
                     pt(1.0f, 1, 1, 1, 0.8f)};
    } else if (name == "mri-head") {
        tf.points = {pt(0.0f, 0, 0, 0, 0), pt(0.12f, 0.75f, 0.5f, 0.4f, 0),
                     pt(0.3f, 0.9f, 0.65f, 0.55f, 0.08f), pt(0.6f, 1.0f, 0.85f, 0.75f, 0.3f),
                     pt(1.0f, 1, 1, 1, 0.6f)};
    } else if (name == "ct-hu") {
        // Absolute Hounsfield units (not normalized): air and lung clear, skin and fat
        // faint, soft tissue (about 40 HU) translucent red, bone (300 HU and up) opaque.
        tf.normalized = false;
        tf.points = {pt(-1000.0f, 0, 0, 0, 0),       pt(-500.0f, 0.85f, 0.55f, 0.45f, 0),
                     pt(-100.0f, 0.9f, 0.6f, 0.5f, 0.01f), pt(40.0f, 0.95f, 0.5f, 0.4f, 0.04f),
                     pt(150.0f, 0.95f, 0.55f, 0.45f, 0.05f), pt(300.0f, 1, 0.95f, 0.85f, 0.5f),
                     pt(3000.0f, 1, 1, 1, 0.9f)};
    } else if (name == "mip-gray" || name == "xray") {
        // Projections of the density: the points are a grey ramp (used only if an explicit
        // --mode dvr overrides the preset's mode); the mode comes with the preset.
        tf.points = {pt(0.0f, 0, 0, 0, 0), pt(1.0f, 1, 1, 1, 0.05f)};
        tf.mode = name == "xray" ? RenderMode::Xray : RenderMode::Mip;
    } else {
        std::string all;
        for (const auto& n : TransferFunction::presetNames()) all += (all.empty() ? "" : ", ") + n;
        throw Error("unknown transfer function preset '" + name + "' (presets: " + all +
                    "; or give a .json file)");
    }
    return tf;
}

}  // namespace

void TransferFunction::validate(const std::string& what) const {
    const TransferFunction& tf = *this;
    if (tf.points.empty()) throw Error(what + ": transfer function has no points");
    if (!(tf.unitDistance >= kMinUnitDistance && tf.unitDistance <= kMaxUnitDistance))
        throw Error(what + ": unit_distance must be a number in [1e-6, 1e6] world units (got " +
                    std::to_string(tf.unitDistance) + ")");
    for (std::size_t n = 0; n < tf.points.size(); ++n) {
        const auto& p = tf.points[n];
        if (!std::isfinite(p.value))
            throw Error(what + ": point " + std::to_string(n) + " has a non-finite value");
        for (int c = 0; c < 4; ++c)
            if (!(p.rgba[c] >= 0.0f && p.rgba[c] <= 1.0f))
                throw Error(what + ": point " + std::to_string(n) +
                            " has a colour or opacity outside [0, 1]");
        if (n > 0 && p.value < tf.points[n - 1].value)
            throw Error(what + ": point values must be non-decreasing (point " + std::to_string(n) +
                        ")");
    }
}

namespace {

bool endsWith(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open transfer function file");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw Error(path + ": cannot read transfer function file");
    return text;
}

}  // namespace

std::vector<std::string> TransferFunction::presetNames() {
    return {"ct-bone", "ct-soft", "ct-hu", "mri-head", "gray-ramp", "mip-gray", "xray"};
}

TransferFunction TransferFunction::preset(const std::string& name) { return makePreset(name); }

TransferFunction TransferFunction::fromJson(const std::string& given) {
    // "FILE.json#Name" picks one preset of a ParaView file.
    std::string path = given, presetName;
    const std::size_t hash = given.rfind(".json#");
    if (hash != std::string::npos) {
        path = given.substr(0, hash + 5);
        presetName = given.substr(hash + 6);
    }
    const std::string text = readText(path);
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const std::exception& e) {
        throw Error(path + ": not valid JSON (" + std::string(e.what()) + ")");
    }
    if (j.is_array() || (j.is_object() && j.contains("RGBPoints")))
        return fromParaView(text, path, presetName);
    if (!presetName.empty())
        throw Error(path + ": '#" + presetName +
                    "' selects a preset of a ParaView file, but this is the project's format");
    if (!j.is_object())
        throw Error(path + ": a transfer function file is a JSON object (or ParaView's array)");
    static const char* const kKeys[] = {"domain", "unit_distance", "mode", "name", "points"};
    for (const auto& item : j.items()) {
        if (std::find_if(std::begin(kKeys), std::end(kKeys),
                         [&](const char* k) { return item.key() == k; }) == std::end(kKeys))
            throw Error(path + ": unknown key \"" + item.key() +
                        "\" (keys: domain, unit_distance, mode, name, points)");
    }
    TransferFunction tf;
    tf.name = path;
    try {
        const std::string domain = j.value("domain", "absolute");
        if (domain != "absolute" && domain != "normalized")
            throw Error(path + ": \"domain\" must be \"absolute\" or \"normalized\"");
        tf.normalized = domain == "normalized";
        tf.unitDistance = j.value("unit_distance", 1.0);
        if (j.contains("name")) tf.name = j["name"].get<std::string>();
        if (j.contains("mode")) {
            try {
                tf.mode = parseMode(j["mode"].get<std::string>());
            } catch (const Error& e) {
                throw Error(path + ": \"mode\": " + e.what());
            }
        }
        if (!j.contains("points") || !j["points"].is_array())
            throw Error(path + ": missing \"points\": [[value, r, g, b, a], ...]");
        for (const auto& p : j["points"]) {
            if (!p.is_array() || p.size() != 5)
                throw Error(path + ": each point must be [value, r, g, b, a]");
            tf.points.push_back(pt(p[0].get<float>(), p[1].get<float>(), p[2].get<float>(),
                                   p[3].get<float>(), p[4].get<float>()));
        }
    } catch (const nlohmann::json::exception& e) {
        throw Error(path + ": bad transfer function (" + std::string(e.what()) + ")");
    }
    tf.validate(path);
    return tf;
}

TransferFunction TransferFunction::load(const std::string& nameOrPath) {
    if (endsWith(nameOrPath, ".json") || nameOrPath.find(".json#") != std::string::npos)
        return fromJson(nameOrPath);
    return preset(nameOrPath);
}

RenderMode modeFor(const TransferFunction& tf, RenderMode chosen, bool explicitMode,
                   std::string* warning) {
    if (!tf.mode || *tf.mode == chosen) return chosen;
    if (!explicitMode) return *tf.mode;
    if (warning)
        *warning = std::string("--mode ") + toString(chosen) + " overrides the mode " +
                   toString(*tf.mode) + " of transfer function '" + tf.name + "'";
    return chosen;
}

TransferFunction TransferFunction::rescaledToData() const {
    if (normalized || points.empty()) return *this;
    TransferFunction tf = *this;
    tf.normalized = true;
    const float lo = points.front().value, span = points.back().value - lo;
    for (auto& p : tf.points) p.value = span > 0 ? (p.value - lo) / span : 0.0f;
    return tf;
}

TransferFunction TransferFunction::resolved(float lo, float hi) const {
    if (!normalized) return *this;
    TransferFunction tf = *this;
    tf.normalized = false;
    const float span = hi > lo ? hi - lo : 1.0f;
    for (auto& p : tf.points) p.value = lo + p.value * span;
    return tf;
}

glm::vec4 TransferFunction::sample(float d) const {
    if (points.empty()) return glm::vec4(0.0f);
    if (!(d > points.front().value)) return points.front().rgba;
    if (!(d < points.back().value)) return points.back().rgba;
    const auto it = std::upper_bound(points.begin(), points.end(), d,
                                     [](float v, const TransferPoint& p) { return v < p.value; });
    const TransferPoint& b = *it;
    const TransferPoint& a = *(it - 1);
    const float span = b.value - a.value;
    const float f = span > 0 ? (d - a.value) / span : 1.0f;
    return a.rgba + f * (b.rgba - a.rgba);
}

float TransferFunction::extinctionFromOpacity(float alpha) const {
    // rho = -ln(1 - alpha) / unit distance, evaluated as -log1p(-alpha) in double: 1 - alpha
    // in float loses every opacity below 6e-8 (alpha = 1e-9 became rho = 0, and 1e-7 came
    // out 19% too opaque). 1 - alpha is clamped below so that alpha = 1 gives a large finite
    // extinction instead of inf; NaN opacities give 0.
    if (!(alpha > 0.0f)) return 0.0f;
    const double a = std::min(double(alpha), 1.0 - double(kMinTransmittance));
    return float(-std::log1p(-a) / unitDistance);
}

bool TransferFunction::invisibleOver(float lo, float hi) const {
    if (points.empty()) return true;
    if (sample(lo).a > 0.0f || sample(hi).a > 0.0f) return false;
    for (const auto& p : points)
        if (p.value > lo && p.value < hi && p.rgba.a > 0.0f) return false;
    return true;
}

}  // namespace splat
