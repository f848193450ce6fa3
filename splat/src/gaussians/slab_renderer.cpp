// `sheet`: the image-aligned sheet-buffer splatter (Mueller & Crawfis 1998) on Gaussians. Slab
// k holds view depths [k h, (k + 1) h) measured from the camera target's plane; along a pixel's ray
// o + t d it is t in [k h / (d.view), (k + 1) h / (d.view)). Each Gaussian's optical depth in a
// slab is exact: 2 amplitude (erf(s (t1 - t*)) - erf(s (t0 - t*))) / 2 (projection.h RayGaussian);
// its emission is that times its colour. Each slab becomes one sample (alpha = 1 - exp(-tau),
// C = E alpha / tau) composited front to back. Within one slab the colours of different
// Gaussians are averaged by optical depth, which is the whole of its error against the
// reference: as h -> 0 it converges to the integral.
#include <atomic>
#include <climits>
#include <cmath>
#include <string>
#include <vector>

#include "renderers.h"
#include "splat/error.h"

namespace splat::gaussians {

namespace {
constexpr double kErfReach = 4.5;            // 1 - erf(4.5) = 2e-10: the Gaussian's whole extent
constexpr std::int64_t kMaxSlabs = 1 << 22;  // per pixel ray
}  // namespace

Image renderSlabs(const GaussianScene& scene, const Projected& p, const TileLists& tiles,
                  const Camera& camera, double slab, double epsilon) {
    const int width = camera.width(), height = camera.height();
    Image image(width, height);
    std::atomic<bool> tooThin{false};
    forEachTile(tiles, [&](int tx, int ty) {
        const int tile = ty * tiles.tilesX + tx;
        std::vector<RayGaussian> gs;
        std::vector<double> tau;
        std::vector<glm::dvec3> emission;
        for (int y = ty * kTile; y < std::min(height, (ty + 1) * kTile); ++y)
            for (int x = tx * kTile; x < std::min(width, (tx + 1) * kTile); ++x) {
                const Ray ray = camera.ray(x + 0.5, y + 0.5);
                gaussiansOnRay(scene, p, tiles.begin(tile), tiles.end(tile), ray, epsilon, gs);
                if (gs.empty()) continue;
                // Ray parameter t of view depth z (from the target's plane: the slab grid is
                // the same for every scene seen by one free camera): z = z_o + t cos.
                const double cosine = glm::dot(ray.dir, camera.view);
                const double zo = glm::dot(ray.origin - camera.target, camera.view);
                auto slabOf = [&](double t) {
                    return std::int64_t(std::floor((zo + t * cosine) / slab));
                };
                // The ray starts at t = 0 (the eye, or the plane in front of the scene).
                const std::int64_t start = slabOf(0.0);
                std::int64_t first = INT64_MAX, last = INT64_MIN;
                for (const RayGaussian& g : gs) {
                    first = std::min(first, std::max(start, slabOf(g.tStar - kErfReach / g.s)));
                    last = std::max(last, slabOf(g.tStar + kErfReach / g.s));
                }
                if (last < first) continue;
                if (last - first + 1 > kMaxSlabs) {
                    tooThin = true;
                    return;
                }
                const std::size_t count = std::size_t(last - first + 1);
                tau.assign(count, 0.0);
                emission.assign(count, glm::dvec3(0.0));
                auto tOf = [&](std::int64_t k) { return (double(k) * slab - zo) / cosine; };
                for (const RayGaussian& g : gs) {
                    const std::int64_t k0 = std::max(start, slabOf(g.tStar - kErfReach / g.s));
                    const std::int64_t k1 = slabOf(g.tStar + kErfReach / g.s);
                    double before = std::erf(g.s * (std::max(0.0, tOf(k0)) - g.tStar));
                    for (std::int64_t k = k0; k <= k1; ++k) {
                        const double after = std::erf(g.s * (tOf(k + 1) - g.tStar));
                        const double d = g.amplitude * (after - before);
                        tau[std::size_t(k - first)] += d;
                        emission[std::size_t(k - first)] += glm::dvec3(g.colour) * d;
                        before = after;
                    }
                }
                FrontToBack out;
                for (std::size_t k = 0; k < count; ++k) out.sheet(tau[k], emission[k]);
                image.at(x, y) = out.pixel();
            }
    });
    if (tooThin)
        throw Error("sheet: slab thickness " + std::to_string(slab) +
                    " makes more than 4M slabs along a ray; use a thicker --slab");
    return image;
}

}  // namespace splat::gaussians
