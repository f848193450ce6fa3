#pragma once
// Helpers of the [techniques] tests.
#include <cmath>
#include <glm/glm.hpp>
#include <vector>

#include "splat/render.h"
#include "splat/synthetic.h"

namespace splat::test {

inline constexpr RendererKind kAllRenderers[] = {RendererKind::Axis, RendererKind::Sheet,
                                                 RendererKind::Reference};

/// Opaque white above `level` (absolute), transparent below: a hard surface.
inline TransferFunction surfaceTf(float level, float alpha = 1.0f,
                                  glm::vec3 colour = glm::vec3(1.0f)) {
    TransferFunction tf;
    tf.name = "surface";
    tf.points = {{level - 0.05f, glm::vec4(colour, 0.0f)},
                 {level + 0.05f, glm::vec4(colour, alpha)},
                 {level + 10.0f, glm::vec4(colour, alpha)}};
    return tf;
}

/// An n^3 volume of ones (spacing 1): a constant cube.
inline Volume onesVolume(int n) {
    Volume v = makeVolume(glm::ivec3(n), glm::dvec3(1.0), "constant");
    for (float& d : v.data) d = 1.0f;
    return v;
}

/// Green (0.2, 0.9, 0.3), transparent at 0 and opaque from 0.5 (absolute) on.
inline TransferFunction greenTf() {
    TransferFunction tf;
    tf.points = {{0.0f, glm::vec4(0.2f, 0.9f, 0.3f, 0.0f)},
                 {0.5f, glm::vec4(0.2f, 0.9f, 0.3f, 1.0f)},
                 {2.0f, glm::vec4(0.2f, 0.9f, 0.3f, 1.0f)}};
    return tf;
}

inline RenderSettings techniqueSettings(RendererKind r, RenderMode m, int size) {
    RenderSettings s;
    s.renderer = r;
    s.mode = m;
    s.camera.width = s.camera.height = size;
    s.threads = 2;
    return s;
}

/// Impact parameter of pixel (x, y)'s ray from the volume centre (world).
inline double impactOf(const Camera& cam, int x, int y) {
    const Ray r = cam.ray(x + 0.5, y + 0.5);
    const glm::dvec3 d = cam.target - r.origin;
    return glm::length(d - glm::dot(d, r.dir) * r.dir);
}

}  // namespace splat::test
