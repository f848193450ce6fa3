#pragma once
// Transfer functions: piecewise-linear RGBA over density. Opacity is given per reference
// length (unit distance) unitDistance in world units, like VTK's scalar opacity unit
// distance, and turned into extinction per world unit with the opacity correction
//   rho = -ln(1 - alpha) / unitDistance.
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

namespace splat {

enum class RenderMode;  // splat/settings.h

struct TransferPoint {
    float value = 0;       ///< density (absolute units after resolve())
    glm::vec4 rgba{0.0f};  ///< colour (not premultiplied) and opacity per unit distance
};

class TransferFunction {
  public:
    std::string name = "custom";
    std::vector<TransferPoint> points;  ///< sorted by value
    double unitDistance = 1.0;          ///< reference length of the opacities, world units
    /// Control point values are fractions of the volume's [min, max] range until resolve()
    /// maps them to absolute densities (presets are normalized; JSON files say which).
    bool normalized = false;
    /// The render mode the function was made for (presets mip-gray, xray; a "mode" key in a
    /// JSON file); none for plain colour maps. An explicit --mode wins (docs/techniques.md).
    std::optional<RenderMode> mode;

    /// Presets: ct-bone, ct-soft, mri-head, gray-ramp (normalized domain); mip-gray (mode
    /// mip) and xray (mode xray) carry their mode.
    static TransferFunction preset(const std::string& name);
    static std::vector<std::string> presetNames();
    /// The project's JSON: {"domain": "absolute"|"normalized", "unit_distance": 1,
    ///   "mode": "dvr"|"mip"|"xray"|"iso", "name": "...", "points": [[value, r, g, b, a], ...]};
    /// or ParaView's colour-map preset JSON (an array of {"Name", "ColorSpace", "RGBPoints",
    /// "Points", ...}; absolute data values). `path` may end in "#Name" to pick one preset
    /// of a ParaView file holding several. Throws splat::Error naming the file and the
    /// problem: unknown keys, non-finite or out-of-range numbers, unsorted points.
    static TransferFunction fromJson(const std::string& path);
    /// ParaView's format, already parsed (`what` names the file in errors).
    static TransferFunction fromParaView(const std::string& jsonText, const std::string& what,
                                         const std::string& presetName = "");
    /// A preset name or a .json path (optionally with "#Name").
    static TransferFunction load(const std::string& nameOrPath);

    /// Throws splat::Error (prefixed by `what`) unless there are points, every value is finite
    /// and non-decreasing, every colour and opacity in [0, 1] and the unit distance in
    /// [kMinUnitDistance, kMaxUnitDistance].
    void validate(const std::string& what) const;

    /// Maps normalized control points onto [lo, hi]; no-op for absolute ones.
    TransferFunction resolved(float lo, float hi) const;
    /// The same function on the normalized domain: its first..last control values become
    /// 0..1, so that resolve() stretches it over the volume's [min, max] (ParaView's
    /// "rescale to data range"; --tf-rescale). No-op for normalized functions.
    TransferFunction rescaledToData() const;

    /// Colour and opacity at density d (clamped at the ends).
    glm::vec4 sample(float d) const;
    /// Extinction per world unit at density d; finite even for opacity 1.
    float extinction(float d) const { return extinctionFromOpacity(sample(d).a); }
    float extinctionFromOpacity(float alpha) const;
    /// True when opacity is zero over the whole closed interval [lo, hi].
    bool invisibleOver(float lo, float hi) const;
};

/// The render mode when the transfer function may carry one (presets mip-gray, xray; a JSON
/// file's "mode"): `chosen` when the mode was chosen explicitly (then `*warning`, if given,
/// receives a line when it differs from the function's), else the function's mode, else
/// `chosen`.
RenderMode modeFor(const TransferFunction& tf, RenderMode chosen, bool explicitMode,
                   std::string* warning = nullptr);

/// Accepted unit distances, world units: outside, the opacity correction overflows float
/// (1e-300 gave NaN pixels) or no ray could ever accumulate opacity.
inline constexpr double kMinUnitDistance = 1e-6, kMaxUnitDistance = 1e6;

/// Largest extinction times unit distance: opacity 1 maps to -ln(kMinTransmittance).
inline constexpr float kMinTransmittance = 1e-7f;

}  // namespace splat
