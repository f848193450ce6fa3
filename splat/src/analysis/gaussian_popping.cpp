// Popping analysis of Gaussian scenes (see splat/gaussian_popping.h).
#include "splat/gaussian_popping.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <set>
#include <unordered_map>

#include "splat/depth.h"

namespace splat {

namespace {

/// The rasterizer's footprint radius of Gaussian i in world units: 3 standard deviations of
/// its largest scale.
double footprintRadius(const GaussianScene& scene, std::size_t i) {
    const glm::vec3 s = scene.scales[i];
    return 3.0 * double(std::max({s.x, s.y, s.z}));
}

/// mu_i - mu_j as a unit vector whose first non-zero component is positive (a swap of i, j
/// and of j, i is the same), rounded to 1e-7 so that the pairs of a lattice share it.
glm::dvec3 swapDirection(const glm::dvec3& d) {
    glm::dvec3 u = d / glm::length(d);
    if (u.x < 0 || (u.x == 0 && (u.y < 0 || (u.y == 0 && u.z < 0)))) u = -u;
    return glm::round(u * 1e7) * 1e-7;
}

struct DirectionLess {
    bool operator()(const glm::dvec3& a, const glm::dvec3& b) const {
        return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
    }
};
using DirectionSet = std::set<glm::dvec3, DirectionLess>;

/// Calls fn(i, j), i < j, for every pair of visible Gaussians whose footprints overlap
/// (|mu_i - mu_j| < r_i + r_j): a uniform grid of cells twice the largest radius, each
/// Gaussian compared with those of its own and the 26 neighbouring cells.
void forEachOverlappingPair(const GaussianScene& scene,
                            const std::function<void(std::size_t, std::size_t)>& fn) {
    std::vector<std::size_t> visible;
    double rMax = 0;
    for (std::size_t i = 0; i < scene.size(); ++i)
        if (scene.opacities[i] >= 1.0f / 255.0f) {
            visible.push_back(i);
            rMax = std::max(rMax, footprintRadius(scene, i));
        }
    if (visible.size() < 2 || !(rMax > 0)) return;
    glm::dvec3 lo, hi;
    scene.bounds(lo, hi);
    const double cell = 2 * rMax;
    auto cellOf = [&](std::size_t i) {
        return glm::ivec3(glm::floor((glm::dvec3(scene.means[i]) - lo) / cell));
    };
    auto key = [](const glm::ivec3& c) {
        return (std::uint64_t(std::uint32_t(c.x) & 0x1fffff) << 42) |
               (std::uint64_t(std::uint32_t(c.y) & 0x1fffff) << 21) |
               std::uint64_t(std::uint32_t(c.z) & 0x1fffff);
    };
    std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells;
    for (std::size_t i : visible) cells[key(cellOf(i))].push_back(i);
    for (std::size_t i : visible) {
        const glm::ivec3 c = cellOf(i);
        const glm::dvec3 mi(scene.means[i]);
        const double ri = footprintRadius(scene, i);
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const auto it = cells.find(key(c + glm::ivec3(dx, dy, dz)));
                    if (it == cells.end()) continue;
                    for (std::size_t j : it->second) {
                        if (j <= i) continue;
                        const double d = glm::length(glm::dvec3(scene.means[j]) - mi);
                        if (d > 0 && d < ri + footprintRadius(scene, j)) fn(i, j);
                    }
                }
    }
}

/// The distinct directions mu_i - mu_j of the overlapping pairs.
DirectionSet swapDirections(const GaussianScene& scene) {
    DirectionSet out;
    forEachOverlappingPair(scene, [&](std::size_t i, std::size_t j) {
        out.insert(swapDirection(glm::dvec3(scene.means[i]) - glm::dvec3(scene.means[j])));
    });
    return out;
}

/// The positions in (positions.front(), positions.back()) where the view direction crosses
/// the plane perpendicular to one of `directions`: sign changes of d . v sampled at 16
/// sub-steps per interval, bisected to 1e-9; within 1e-4 of each other one
/// (directions rounded to 1e-7 move a swap by up to ~1e-5 degrees).
std::vector<double> orderSwaps(const GaussianScene& scene, const std::vector<double>& positions,
                               const std::function<CameraParams(double)>& cameraAt) {
    const DirectionSet directions = swapDirections(scene);
    const Volume geometry = scene.geometry();
    auto viewAt = [&](double u) { return Camera(cameraAt(u), geometry).view; };
    constexpr int kSub = 16;
    std::vector<double> at;
    for (std::size_t n = 0; n + 1 < positions.size(); ++n)
        for (int q = 0; q < kSub; ++q)
            at.push_back(positions[n] + (positions[n + 1] - positions[n]) * q / kSub);
    at.push_back(positions.back());
    std::vector<glm::dvec3> views;
    for (double u : at) views.push_back(viewAt(u));
    std::vector<double> out;
    for (const glm::dvec3& d : directions)
        for (std::size_t m = 0; m + 1 < at.size(); ++m) {
            const bool before = glm::dot(d, views[m]) < 0;
            if ((glm::dot(d, views[m + 1]) < 0) == before) continue;
            double a = at[m], b = at[m + 1];
            while (b - a > 1e-9) {
                const double mid = 0.5 * (a + b);
                ((glm::dot(d, viewAt(mid)) < 0) == before ? a : b) = mid;
            }
            out.push_back(0.5 * (a + b));
        }
    std::sort(out.begin(), out.end());
    std::vector<double> merged;
    for (double u : out)
        if (merged.empty() || u - merged.back() > 1e-4) merged.push_back(u);
    return merged;
}

RendererKind roleOf(GaussianRenderer g) {
    switch (g) {
        case GaussianRenderer::Sheet:
            return RendererKind::Sheet;
        case GaussianRenderer::Reference:
            return RendererKind::Reference;
        default:
            return RendererKind::Axis;
    }
}

/// `options` with the Gaussian renderers in their roles, frames from renderGaussians and the
/// order swaps as the predicted events.
PoppingOptions gaussianOptions(const GaussianScene& scene,
                               const std::vector<GaussianRenderer>& renderers,
                               const GaussianRenderOptions& render, PoppingOptions options,
                               std::vector<double> predicted) {
    if (renderers.empty()) throw Error("popping: no renderer to analyse");
    options.renderers.clear();
    options.names.clear();
    for (GaussianRenderer g : renderers) {
        options.renderers.push_back(roleOf(g));
        options.names.push_back(gaussianRendererName(g));
    }
    options.renderFrame = nullptr;
    options.renderNamed = [&scene, renderers, render](std::size_t k, const RenderSettings& s,
                                                      RenderStats* stats) {
        GaussianRenderOptions g = render;
        g.renderer = renderers[k];
        const auto t0 = std::chrono::steady_clock::now();
        Image image = renderGaussians(scene, s.camera, g);
        if (stats)
            stats->milliseconds =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                    .count();
        return image;
    };
    // The temporal FLIP warps frames with the depth of the scene's exact reference.
    if (!options.depthFrame)
        options.depthFrame = [&scene](const CameraParams& camera) {
            return gaussianReferenceDepth(scene, camera);
        };
    options.predicted = std::move(predicted);
    options.predictedName = "order swap";
    options.truth = Truth::Point;
    options.scene = scene.source + ", " + std::to_string(scene.size()) + " Gaussians, SH degree " +
                    std::to_string(scene.shDegree);
    return options;
}

/// The analyzer's settings of a Gaussian scene: the camera and the threads.
RenderSettings gaussianSettings(const CameraParams& camera, const GaussianRenderOptions& render) {
    RenderSettings s;
    s.camera = camera;
    s.threads = render.threads;
    return s;
}

}  // namespace

std::vector<GaussianRenderer> parseGaussianRenderers(const std::string& list) {
    std::vector<GaussianRenderer> out;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t comma = std::min(list.find(',', start), list.size());
        const GaussianRenderer g = parseGaussianRenderer(list.substr(start, comma - start));
        if (std::find(out.begin(), out.end(), g) != out.end())
            throw Error(std::string("renderer '") + gaussianRendererName(g) + "' listed twice");
        out.push_back(g);
        start = comma + 1;
    }
    return out;
}

std::vector<double> predictOrderSwaps(const GaussianScene& scene, const Sweep& sweep) {
    return orderSwaps(scene, sweep.angles(), [&](double a) { return sweep.camera(a); });
}

std::vector<double> predictOrderSwaps(const GaussianScene& scene, const CameraPath& path) {
    if (path.views.size() < 2) return {};
    std::vector<double> u(path.views.size());
    for (std::size_t n = 0; n < u.size(); ++n) u[n] = double(n);
    const std::size_t last = path.views.size() - 1;
    return orderSwaps(scene, u, [&](double x) {
        const std::size_t a = std::min(last - 1, std::size_t(std::max(0.0, x)));
        return interpolateCamera(path.views[a], path.views[a + 1],
                                 std::clamp(x - double(a), 0.0, 1.0));
    });
}

PoppingResult analyzeGaussianPopping(const GaussianScene& scene, const Sweep& sweep,
                                     const std::vector<GaussianRenderer>& renderers,
                                     const GaussianRenderOptions& render, PoppingOptions options) {
    const PoppingOptions o = gaussianOptions(scene, renderers, render, std::move(options),
                                             predictOrderSwaps(scene, sweep));
    return analyzePopping(scene.geometry(), gaussianSettings(sweep.base, render), sweep, o);
}

PoppingResult analyzeGaussianPopping(const GaussianScene& scene, const CameraPath& path,
                                     const std::vector<GaussianRenderer>& renderers,
                                     const GaussianRenderOptions& render, PoppingOptions options) {
    if (path.views.empty()) throw Error("popping: an empty camera path");
    const PoppingOptions o = gaussianOptions(scene, renderers, render, std::move(options),
                                             predictOrderSwaps(scene, path));
    return analyzePopping(scene.geometry(), gaussianSettings(path.views.front(), render), path, o);
}

}  // namespace splat
