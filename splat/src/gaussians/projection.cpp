// Projection and tile binning of Gaussians (projection.h), after the reference 3DGS
// rasterizer's preprocess and duplicate-with-keys stages (Kerbl et al. 2023): EWA projection
// (Zwicker et al. 2002) of Sigma = R S^2 R^T with the perspective Jacobian at the mean
// (its x/z, y/z clamped to 1.3 times the half field of view), 0.3 px^2 added on the diagonal.
#include "projection.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "splat/error.h"

namespace splat::gaussians {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kNear = 0.2;

// Columns: the Gaussian's local axes (rotation of the unit quaternion (w, x, y, z)).
glm::dmat3 rotation(const glm::vec4& q) {
    const double r = q[0], x = q[1], y = q[2], z = q[3];
    glm::dmat3 m;
    m[0] = {1 - 2 * (y * y + z * z), 2 * (x * y + r * z), 2 * (x * z - r * y)};
    m[1] = {2 * (x * y - r * z), 1 - 2 * (x * x + z * z), 2 * (y * z + r * x)};
    m[2] = {2 * (x * z + r * y), 2 * (y * z - r * x), 1 - 2 * (x * x + y * y)};
    return m;
}
}  // namespace

ViewFrame viewFrame(const Camera& camera) {
    ViewFrame f;
    f.eye = camera.eye;
    f.right = camera.right;
    f.down = -camera.up;
    f.view = camera.view;
    f.perspective = camera.perspective();
    f.width = camera.width();
    f.height = camera.height();
    f.focalPixels = f.perspective ? camera.focal / camera.pixelSize : 1.0 / camera.pixelSize;
    f.limitX = 1.3 * 0.5 * f.width / f.focalPixels;
    f.limitY = 1.3 * 0.5 * f.height / f.focalPixels;
    return f;
}

Projected project(const GaussianScene& scene, const ViewFrame& f, Footprint footprint,
                  double epsilon, bool rays) {
    const std::size_t n = scene.size();
    Projected p;
    p.centre.resize(n);
    p.conic.resize(n);
    p.depth.resize(n);
    p.radius.assign(n, 0);
    p.colour.resize(n);
    p.opacity.assign(scene.opacities.begin(), scene.opacities.end());
    const bool ray = footprint == Footprint::Volume;
    if (rays) {
        p.precision.resize(n);
        p.density.assign(n, 0.0);
    }
    const glm::dmat3 toView = glm::transpose(glm::dmat3(f.right, f.down, f.view));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const glm::dvec3 mean(scene.means[i]);
            const glm::dvec3 v = toView * (mean - f.eye);
            p.depth[i] = float(v.z);
            if (!(v.z > kNear)) continue;
            const glm::dmat3 r = rotation(scene.rotations[i]);
            const glm::dvec3 s(scene.scales[i]);
            const glm::dmat3 rs(r[0] * s.x, r[1] * s.y, r[2] * s.z);
            const glm::dmat3 sigmaView =
                toView * (rs * glm::transpose(rs)) * glm::transpose(toView);
            glm::dmat3 j(0.0);  // 2 x 3 Jacobian in the upper rows (glm: j[col][row])
            if (f.perspective) {
                const double tx = std::clamp(v.x / v.z, -f.limitX, f.limitX) * v.z;
                const double ty = std::clamp(v.y / v.z, -f.limitY, f.limitY) * v.z;
                j[0][0] = f.focalPixels / v.z;
                j[1][1] = f.focalPixels / v.z;
                j[2][0] = -f.focalPixels * tx / (v.z * v.z);
                j[2][1] = -f.focalPixels * ty / (v.z * v.z);
                p.centre[i] = {float(0.5 * f.width + f.focalPixels * v.x / v.z),
                               float(0.5 * f.height + f.focalPixels * v.y / v.z)};
            } else {
                j[0][0] = j[1][1] = f.focalPixels;
                p.centre[i] = {float(0.5 * f.width + f.focalPixels * v.x),
                               float(0.5 * f.height + f.focalPixels * v.y)};
            }
            const glm::dmat3 cov = j * sigmaView * glm::transpose(j);
            const glm::dvec3 dir = f.perspective ? glm::normalize(mean - f.eye) : f.view;
            p.colour[i] = gaussianColour(scene, i, glm::vec3(dir));
            const double tauPeak = -std::log1p(-std::min(double(scene.opacities[i]), 0.99));
            if (rays) {
                const glm::dmat3 pr(r[0] / (s.x * s.x), r[1] / (s.y * s.y), r[2] / (s.z * s.z));
                const glm::dmat3 prec = pr * glm::transpose(r);
                p.precision[i] = {prec[0][0], prec[1][0], prec[2][0],
                                  prec[1][1], prec[2][1], prec[2][2]};
                p.density[i] = tauPeak * std::sqrt(glm::dot(dir, prec * dir) / (2 * kPi));
            }
            // The conic is always the rasterizers' (dilated by 0.3 px^2).
            const double b = cov[1][0], da = cov[0][0] + 0.3, dc = cov[1][1] + 0.3;
            const double ddet = da * dc - b * b;
            if (!(ddet > 0)) continue;
            p.conic[i] = {float(dc / ddet), float(-b / ddet), float(da / ddet)};
            double radiusScale = 3.0, a = da, c = dc;
            if (ray) {
                // Volume footprint: the marginal of the undilated covariance, exact for
                // orthographic rays (perspective: 25% and a pixel of margin).
                if (!(tauPeak > epsilon)) continue;
                radiusScale = std::sqrt(2.0 * std::log(tauPeak / epsilon));
                if (f.perspective) radiusScale *= 1.25;
                a = cov[0][0];
                c = cov[1][1];
            }
            const double det = a * c - b * b;
            const double mid = 0.5 * (a + c);
            const double lambda = mid + std::sqrt(std::max(0.1, mid * mid - det));
            p.radius[i] = int(std::ceil(radiusScale * std::sqrt(lambda))) + (ray && f.perspective);
        }
    });
    return p;
}

TileLists binToTiles(const Projected& p, int width, int height) {
    TileLists t;
    t.tilesX = (width + kTile - 1) / kTile;
    t.tilesY = (height + kTile - 1) / kTile;
    const std::size_t n = p.depth.size();
    if (n > std::size_t(UINT32_MAX)) throw Error("too many Gaussians for one frame");
    // Keys: depth (> 0.2, so its float bits order as unsigned integers), then index.
    std::vector<std::uint64_t> keys;
    keys.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        if (p.radius[i] <= 0) continue;
        std::uint32_t bits;
        std::memcpy(&bits, &p.depth[i], 4);
        keys.push_back(std::uint64_t(bits) << 32 | std::uint64_t(i));
    }
    tbb::parallel_sort(keys.begin(), keys.end());
    // The tile rectangle of 3DGS's getRect, whose pixel centres sit at integers (ours - 0.5).
    auto rect = [&](std::size_t i, glm::ivec4& r) {
        const double x = p.centre[i].x - 0.5, y = p.centre[i].y - 0.5, rad = p.radius[i];
        auto lo = [](double v, int hi) { return std::min(hi, std::max(0, int(v / kTile))); };
        auto up = [](double v, int hi) {
            return std::min(hi, std::max(0, int((v + kTile - 1) / kTile)));
        };
        r = {lo(x - rad, t.tilesX), lo(y - rad, t.tilesY), up(x + rad, t.tilesX),
             up(y + rad, t.tilesY)};
        return r.x < r.z && r.y < r.w;
    };
    t.offsets.assign(std::size_t(t.tilesX) * t.tilesY + 1, 0);
    glm::ivec4 r;
    for (std::uint64_t key : keys) {
        const std::size_t i = std::size_t(key & 0xffffffffu);
        if (!rect(i, r)) continue;
        for (int y = r.y; y < r.w; ++y)
            for (int x = r.x; x < r.z; ++x) ++t.offsets[std::size_t(y) * t.tilesX + x + 1];
    }
    for (std::size_t k = 1; k < t.offsets.size(); ++k) t.offsets[k] += t.offsets[k - 1];
    t.ids.resize(t.offsets.back());
    std::vector<std::uint64_t> fill(t.offsets.begin(), t.offsets.end() - 1);
    for (std::uint64_t key : keys) {
        const std::uint32_t i = std::uint32_t(key & 0xffffffffu);
        if (!rect(i, r)) continue;
        for (int y = r.y; y < r.w; ++y)
            for (int x = r.x; x < r.z; ++x) t.ids[fill[std::size_t(y) * t.tilesX + x]++] = i;
    }
    return t;
}

void forEachTile(const TileLists& tiles, const std::function<void(int, int)>& fn) {
    tbb::parallel_for(0, tiles.tilesX * tiles.tilesY,
                      [&](int k) { fn(k % tiles.tilesX, k / tiles.tilesX); });
}

void forEachPixelRay(const GaussianScene& scene, const Projected& projected,
                     const TileLists& tiles, const Camera& camera, double epsilon,
                     const std::function<void(int, int, const std::vector<RayGaussian>&)>& fn) {
    const int width = camera.width(), height = camera.height();
    forEachTile(tiles, [&](int tx, int ty) {
        const int tile = ty * tiles.tilesX + tx;
        std::vector<RayGaussian> gs;
        for (int y = ty * kTile; y < std::min(height, (ty + 1) * kTile); ++y)
            for (int x = tx * kTile; x < std::min(width, (tx + 1) * kTile); ++x) {
                const Ray ray = camera.ray(x + 0.5, y + 0.5);
                gaussiansOnRay(scene, projected, tiles.begin(tile), tiles.end(tile), ray, epsilon,
                               gs);
                if (!gs.empty()) fn(x, y, gs);
            }
    });
}

std::vector<RayGaussian>& gaussiansOnRay(const GaussianScene& scene, const Projected& projected,
                                         const std::uint32_t* begin, const std::uint32_t* end,
                                         const Ray& ray, double epsilon,
                                         std::vector<RayGaussian>& out) {
    out.clear();
    for (const std::uint32_t* id = begin; id != end; ++id) {
        const RayGaussian g = alongRay(projected, scene.means[*id], *id, ray);
        if (2 * g.amplitude > epsilon) out.push_back(g);
    }
    return out;
}

RayGaussian alongRay(const Projected& p, const glm::vec3& mean, std::size_t i, const Ray& ray) {
    const auto& q = p.precision[i];
    const glm::dmat3 prec(q[0], q[1], q[2], q[1], q[3], q[4], q[2], q[4], q[5]);
    const glm::dvec3 d = ray.dir, m = glm::dvec3(mean) - ray.origin;
    const glm::dvec3 pd = prec * d;
    const double a = glm::dot(d, pd), b = glm::dot(pd, m);
    const double tStar = b / a;
    const double mahal = std::max(0.0, glm::dot(m, prec * m) - b * tStar);
    return {tStar, std::sqrt(0.5 * a),
            p.density[i] * std::exp(-0.5 * mahal) * std::sqrt(kPi / (2 * a)), p.colour[i]};
}

}  // namespace splat::gaussians
