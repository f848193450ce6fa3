#pragma once
// Transfer functions: piecewise-linear RGBA over density. Opacity is given per reference
// length (unit distance) unitDistance in world units, like VTK's scalar opacity unit
// distance, and turned into extinction per world unit with the opacity correction
//   rho = -ln(1 - alpha) / unitDistance.
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace splat {

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

    /// Presets: ct-bone, ct-soft, mri-head, gray-ramp (normalized domain).
    static TransferFunction preset(const std::string& name);
    static std::vector<std::string> presetNames();
    /// JSON: {"domain": "absolute"|"normalized", "unit_distance": 1,
    ///        "points": [[value, r, g, b, a], ...]}. Throws splat::Error on bad files.
    static TransferFunction fromJson(const std::string& path);
    /// A preset name or a .json path.
    static TransferFunction load(const std::string& nameOrPath);

    /// Maps normalized control points onto [lo, hi]; no-op for absolute ones.
    TransferFunction resolved(float lo, float hi) const;

    /// Colour and opacity at density d (clamped at the ends).
    glm::vec4 sample(float d) const;
    /// Extinction per world unit at density d; finite even for opacity 1.
    float extinction(float d) const { return extinctionFromOpacity(sample(d).a); }
    float extinctionFromOpacity(float alpha) const;
    /// True when opacity is zero over the whole closed interval [lo, hi].
    bool invisibleOver(float lo, float hi) const;
};

/// Largest extinction times unit distance: opacity 1 maps to -ln(kMinTransmittance).
inline constexpr float kMinTransmittance = 1e-7f;

}  // namespace splat
