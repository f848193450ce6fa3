// `3dgs-pixel`: the rasterizer's alphas (rasterizer.cpp), blended per pixel in the order of
// each Gaussian's depth of maximum response along the pixel's ray,
// t* = d^T P (mu - o) / d^T P d (StopThePop, Radl et al. 2024, the exact per-pixel sort of
// its hierarchical approximation). No global order: two Gaussians swap where their t* cross
// on the ray, which moves continuously with the view.
#include <algorithm>
#include <tuple>
#include <vector>

#include "renderers.h"

namespace splat::gaussians {

namespace {
struct Hit {
    double tStar;
    std::uint32_t order;  // place in the tile's depth-sorted list (ties)
    float alpha;
    glm::vec3 colour;
};
}  // namespace

Image rasterizePixelSorted(const GaussianScene& scene, const Projected& p, const TileLists& tiles,
                           const Camera& camera) {
    const int width = camera.width(), height = camera.height();
    Image image(width, height);
    forEachTile(tiles, [&](int tx, int ty) {
        const int tile = ty * tiles.tilesX + tx;
        const std::uint32_t *begin = tiles.begin(tile), *end = tiles.end(tile);
        std::vector<Hit> hits;
        for (int y = ty * kTile; y < std::min(height, (ty + 1) * kTile); ++y)
            for (int x = tx * kTile; x < std::min(width, (tx + 1) * kTile); ++x) {
                const glm::vec2 pixel(float(x) + 0.5f, float(y) + 0.5f);
                const Ray ray = camera.ray(x + 0.5, y + 0.5);
                hits.clear();
                for (const std::uint32_t* id = begin; id != end; ++id) {
                    const glm::vec2 d = p.centre[*id] - pixel;
                    const glm::vec3 con = p.conic[*id];
                    const float power =
                        -0.5f * (con.x * d.x * d.x + con.z * d.y * d.y) - con.y * d.x * d.y;
                    if (power > 0.0f) continue;
                    const float alpha = std::min(0.99f, p.opacity[*id] * std::exp(power));
                    if (alpha < 1.0f / 255.0f) continue;
                    const double tStar = alongRay(p, scene.means[*id], *id, ray).tStar;
                    hits.push_back({tStar, std::uint32_t(id - begin), alpha, p.colour[*id]});
                }
                std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) {
                    return std::tie(a.tStar, a.order) < std::tie(b.tStar, b.order);
                });
                float t = 1.0f;
                glm::vec3 c(0.0f);
                for (const Hit& h : hits) {
                    const float next = t * (1 - h.alpha);
                    if (next < 0.0001f) break;
                    c += h.colour * (h.alpha * t);
                    t = next;
                }
                image.at(x, y) = glm::vec4(c, 1.0f - t);
            }
    });
    return image;
}

}  // namespace splat::gaussians
