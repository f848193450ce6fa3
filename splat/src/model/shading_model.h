#pragma once
// The one shading model (splat/settings.h, Shading): Blinn-Phong with ambient, diffuse,
// specular and shininess, two-sided, the light fixed to the camera or given in world space.
// Every renderer and mode calls these two functions: pre-classified emission
// (shadeEmission), post-classified and iso samples (compositing policies) and the reference.
#include <cmath>
#include <glm/glm.hpp>

#include "splat/settings.h"

namespace splat {

/// Light and half vector of one view: l towards the light, h between l and the eye.
struct LightFrame {
    glm::vec3 l{0.0f, 0.0f, 1.0f}, h{0.0f, 0.0f, 1.0f};
    bool headlight = true;  ///< l == h == -view
};

inline LightFrame lightFrame(const Shading& sh, const glm::dvec3& view) {
    const glm::vec3 eye = -glm::vec3(view);
    if (sh.headlight) return {eye, eye, true};
    const float len = glm::length(sh.light);
    const glm::vec3 l = len > 0.0f ? sh.light / len : eye;
    const glm::vec3 h = l + eye;
    const float hl = glm::length(h);
    return {l, hl > 0.0f ? h / hl : l, false};
}

/// Diffuse factor (ambient + diffuse |n.l|) and specular term (specular |n.h|^shininess) for
/// the unit normal n (n = 0: ambient only, no highlight).
struct LightTerms {
    float diffuse, specular;
};
inline LightTerms blinnPhong(const Shading& sh, const LightFrame& lf, float nx, float ny,
                             float nz) {
    const float c = std::abs(nx * lf.l.x + ny * lf.l.y + nz * lf.l.z);
    const float ch = lf.headlight ? c : std::abs(nx * lf.h.x + ny * lf.h.y + nz * lf.h.z);
    return {sh.ambient + sh.diffuse * c,
            ch > 0.0f ? sh.specular * std::exp(sh.shininess * std::log(ch)) : 0.0f};
}

/// blinnPhong with a gradient (any length) instead of a unit normal.
inline LightTerms blinnPhongGradient(const Shading& sh, const LightFrame& lf, float gx, float gy,
                                     float gz) {
    const float len = std::sqrt(gx * gx + gy * gy + gz * gz);
    if (!(len > 0.0f)) return blinnPhong(sh, lf, 0.0f, 0.0f, 0.0f);
    const float inv = 1.0f / len;
    return blinnPhong(sh, lf, gx * inv, gy * inv, gz * inv);
}

/// Edge enhancement factor for the gradient magnitude m = |grad| / G (splat/settings.h).
inline float edgeFactor(const EdgeEnhancement& e, float m) {
    const float mm = std::min(std::max(m, 0.0f), 1.0f);
    const float p = e.exponent == 1.0f ? mm : std::pow(mm, e.exponent);
    return std::max(0.0f, 1.0f + e.gain * (p - 1.0f));
}

}  // namespace splat
