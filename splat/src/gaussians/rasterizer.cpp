// `3dgs`: the reference 3D Gaussian Splatting rasterizer's blending (Kerbl et al. 2023), per
// pixel over its tile's Gaussians in global depth order: alpha = min(0.99, o G) with
// G = exp(-d^T conic d / 2) at the pixel centre, alpha < 1/255 skipped, and the pixel done
// once the transmittance would fall below 1e-4 (that Gaussian not added). Float throughout,
// as the CUDA code.
#include "renderers.h"

namespace splat::gaussians {

Image rasterize(const Projected& p, const TileLists& tiles, int width, int height) {
    Image image(width, height);
    forEachTile(tiles, [&](int tx, int ty) {
        const int tile = ty * tiles.tilesX + tx;
        const std::uint32_t *begin = tiles.begin(tile), *end = tiles.end(tile);
        for (int y = ty * kTile; y < std::min(height, (ty + 1) * kTile); ++y)
            for (int x = tx * kTile; x < std::min(width, (tx + 1) * kTile); ++x) {
                const glm::vec2 pixel(float(x) + 0.5f, float(y) + 0.5f);
                float t = 1.0f;
                glm::vec3 c(0.0f);
                for (const std::uint32_t* id = begin; id != end; ++id) {
                    const glm::vec2 d = p.centre[*id] - pixel;
                    const glm::vec3 con = p.conic[*id];
                    const float power =
                        -0.5f * (con.x * d.x * d.x + con.z * d.y * d.y) - con.y * d.x * d.y;
                    if (power > 0.0f) continue;
                    const float alpha = std::min(0.99f, p.opacity[*id] * std::exp(power));
                    if (alpha < 1.0f / 255.0f) continue;
                    const float next = t * (1 - alpha);
                    if (next < 0.0001f) break;
                    c += p.colour[*id] * (alpha * t);
                    t = next;
                }
                image.at(x, y) = glm::vec4(c, 1.0f - t);
            }
    });
    return image;
}

}  // namespace splat::gaussians
