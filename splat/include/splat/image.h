#pragma once
// An RGBA float image, row 0 at the top; pixel (x, y) has its centre at (x + 0.5, y + 0.5).
// Colour is premultiplied by alpha.
#include <cstddef>
#include <glm/glm.hpp>
#include <vector>

namespace splat {

struct Image {
    int width = 0, height = 0;
    std::vector<glm::vec4> pixels;

    Image() = default;
    Image(int w, int h, const glm::vec4& fill = glm::vec4(0.0f))
        : width(w), height(h), pixels(std::size_t(w) * std::size_t(h), fill) {}
    glm::vec4& at(int x, int y) { return pixels[std::size_t(y) * width + x]; }
    const glm::vec4& at(int x, int y) const { return pixels[std::size_t(y) * width + x]; }
};

}  // namespace splat
