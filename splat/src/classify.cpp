// Classification: voxels -> splat list, keeping only the voxels the scene needs.
#include "splat/classify.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "splat/error.h"

namespace splat {

namespace {

constexpr int kBrick = 8;

// Post-classification and the transfer-function-free modes need every non-zero voxel
// whose neighbourhood can become visible. A brick is needed when the transfer function
// is visible somewhere in the value range of the brick widened by the kernel radius
// (and by 0, since near the border the kernel weights sum to less than 1).
std::vector<char> neededBricks(const Volume& v, const TransferFunction& tf, int pad,
                               glm::ivec3& bricks) {
    bricks = (v.dims + kBrick - 1) / kBrick;
    std::vector<char> need(std::size_t(bricks.x) * bricks.y * bricks.z, 0);
    tbb::parallel_for(0, bricks.z, [&](int bz) {
        for (int by = 0; by < bricks.y; ++by)
            for (int bx = 0; bx < bricks.x; ++bx) {
                const glm::ivec3 b(bx, by, bz);
                const glm::ivec3 lo = glm::max(b * kBrick - pad, glm::ivec3(0));
                const glm::ivec3 hi = glm::min((b + 1) * kBrick + pad, v.dims);
                float mn = 0.0f, mx = 0.0f;
                for (int k = lo.z; k < hi.z; ++k)
                    for (int j = lo.y; j < hi.y; ++j)
                        for (int i = lo.x; i < hi.x; ++i) {
                            const float d = v.at(i, j, k);
                            mn = std::min(mn, d);
                            mx = std::max(mx, d);
                        }
                need[(std::size_t(bz) * bricks.y + by) * bricks.x + bx] = !tf.invisibleOver(mn, mx);
            }
    });
    return need;
}

}  // namespace

std::size_t SplatList::bytes() const {
    return size() * (3 * sizeof(float) + 3 * sizeof(std::uint16_t) + 5 * sizeof(float));
}

SplatList classify(const Volume& volume, const TransferFunction& tf, RenderMode mode,
                   Classification classification, double radius) {
    const glm::ivec3 d = volume.dims;
    if (d.x > 65535 || d.y > 65535 || d.z > 65535)
        throw Error("volume dimension above 65535 is not supported by the splat list");
    if (tf.normalized) throw Error("internal: transfer function must be resolved before classification");

    const bool usesTf = mode == RenderMode::Dvr;
    const bool pre = usesTf && classification == Classification::Pre;
    glm::ivec3 bricks(0);
    std::vector<char> need;
    if (usesTf && !pre) need = neededBricks(volume, tf, int(std::ceil(radius)), bricks);

    auto keep = [&](int i, int j, int k, float value) {
        if (pre) return tf.extinction(value) > 0.0f;
        if (value == 0.0f) return false;
        if (need.empty()) return true;
        return need[(std::size_t(k / kBrick) * bricks.y + j / kBrick) * bricks.x + i / kBrick] != 0;
    };

    // Two passes over z-slices (count, then fill) keep the list in (k, j, i) order for
    // any thread count.
    std::vector<std::size_t> count(std::size_t(d.z) + 1, 0);
    tbb::parallel_for(0, d.z, [&](int k) {
        std::size_t n = 0;
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) n += keep(i, j, k, volume.at(i, j, k));
        count[std::size_t(k) + 1] = n;
    });
    for (int k = 0; k < d.z; ++k) count[std::size_t(k) + 1] += count[std::size_t(k)];

    SplatList s;
    const std::size_t n = count.back();
    s.voxels = volume.voxelCount();
    for (auto* a : {&s.x, &s.y, &s.z, &s.density, &s.extinction, &s.r, &s.g, &s.b}) a->resize(n);
    for (auto* a : {&s.i, &s.j, &s.k}) a->resize(n);
    tbb::parallel_for(0, d.z, [&](int k) {
        std::size_t o = count[std::size_t(k)];
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                const float value = volume.at(i, j, k);
                if (!keep(i, j, k, value)) continue;
                const glm::dvec3 w = volume.world(glm::dvec3(i, j, k));
                s.x[o] = float(w.x);
                s.y[o] = float(w.y);
                s.z[o] = float(w.z);
                s.i[o] = std::uint16_t(i);
                s.j[o] = std::uint16_t(j);
                s.k[o] = std::uint16_t(k);
                s.density[o] = value;
                if (usesTf) {
                    const glm::vec4 c = tf.sample(value);
                    const float rho = tf.extinctionFromOpacity(c.a);
                    s.extinction[o] = rho;
                    s.r[o] = c.r * rho;
                    s.g[o] = c.g * rho;
                    s.b[o] = c.b * rho;
                } else {
                    s.extinction[o] = s.r[o] = s.g[o] = s.b[o] = 0.0f;
                }
                ++o;
            }
    });
    return s;
}

}  // namespace splat
