// `3dgs`: the reference 3D Gaussian Splatting rasterizer's blending (Kerbl et al. 2023), per
// pixel over its tile's Gaussians in global depth order: alpha = min(0.99, o G) with
// G = exp(-d^T conic d / 2) at the pixel centre, alpha < 1/255 skipped, and the pixel done
// once the transmittance would fall below 1e-4 (that Gaussian not added). Float throughout,
// as the CUDA code. A tile first copies its Gaussians into one packed array (as the CUDA code
// loads batches into shared memory), so its 256 pixels read them in order.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <vector>

#include "renderers.h"

namespace splat::gaussians {

namespace {

struct Packed {
    glm::vec2 centre;
    glm::vec3 conic;
    float opacity;
    /// Below this exponent alpha < 1/255 for certain (ln(1 / (255 o)) less a margin), so the
    /// exponential is not evaluated; nearer the edge it is, and the test is the reference's.
    float skipBelow;
    glm::vec3 colour;
};

/// Packed::skipBelow per Gaussian, once per frame (a Gaussian lands in several tiles).
std::vector<float> skipExponents(const Projected& p) {
    std::vector<float> skip(p.opacity.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, skip.size(), 65536), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const float o = p.opacity[i];
            skip[i] = o > 0 ? std::log(1.0f / (255.0f * o)) - 1e-3f : -INFINITY;
        }
    });
    return skip;
}

}  // namespace

Image rasterize(const Projected& p, const TileLists& tiles, int width, int height) {
    Image image(width, height);
    const std::vector<float> skip = skipExponents(p);
    forEachTile(tiles, [&](int tx, int ty) {
        const int tile = ty * tiles.tilesX + tx;
        std::vector<Packed> local;
        local.reserve(std::size_t(tiles.end(tile) - tiles.begin(tile)));
        for (const std::uint32_t* id = tiles.begin(tile); id != tiles.end(tile); ++id)
            local.push_back(
                {p.centre[*id], p.conic[*id], p.opacity[*id], skip[*id], p.colour[*id]});
        for (int y = ty * kTile; y < std::min(height, (ty + 1) * kTile); ++y)
            for (int x = tx * kTile; x < std::min(width, (tx + 1) * kTile); ++x) {
                const glm::vec2 pixel(float(x) + 0.5f, float(y) + 0.5f);
                float t = 1.0f;
                glm::vec3 c(0.0f);
                for (const Packed& g : local) {
                    const glm::vec2 d = g.centre - pixel;
                    const float power = -0.5f * (g.conic.x * d.x * d.x + g.conic.z * d.y * d.y) -
                                        g.conic.y * d.x * d.y;
                    if (power > 0.0f || power < g.skipBelow) continue;
                    const float alpha = std::min(0.99f, g.opacity * std::exp(power));
                    if (alpha < 1.0f / 255.0f) continue;
                    const float next = t * (1 - alpha);
                    if (next < 0.0001f) break;
                    c += g.colour * (alpha * t);
                    t = next;
                }
                image.at(x, y) = glm::vec4(c, 1.0f - t);
            }
    });
    return image;
}

}  // namespace splat::gaussians
