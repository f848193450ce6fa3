// Shared pieces of the splatters (see splatter.h) and the transfer table.
#include "splatter.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace splat {

void orderByKey(const std::vector<std::uint32_t>& key, std::uint32_t keys,
                std::vector<std::uint32_t>& order) {
    std::vector<std::uint32_t> start(std::size_t(keys) + 1, 0);
    for (std::uint32_t k : key) ++start[std::size_t(k) + 1];
    for (std::size_t k = 0; k < keys; ++k) start[k + 1] += start[k];
    order.resize(key.size());
    for (std::size_t s = 0; s < key.size(); ++s) order[start[key[s]]++] = std::uint32_t(s);
}

SplatList sortedBySlice(const SplatList& s, int axis) {
    const std::vector<std::uint16_t>& index = axis == 0 ? s.i : (axis == 1 ? s.j : s.k);
    std::uint32_t slices = 0;
    for (std::uint16_t v : index) slices = std::max<std::uint32_t>(slices, v + 1u);
    std::vector<std::uint32_t> order;
    orderByKey(std::vector<std::uint32_t>(index.begin(), index.end()), slices, order);
    SplatList out;
    out.voxels = s.voxels;
    auto gather = [&](const auto& from, auto& to) {
        to.resize(from.size());
        if (from.empty()) return;
        tbb::parallel_for(std::size_t(0), order.size(), std::size_t(1) << 16, [&](std::size_t b) {
            const std::size_t e = std::min(order.size(), b + (std::size_t(1) << 16));
            for (std::size_t n = b; n < e; ++n) to[n] = from[order[n]];
        });
    };
    gather(s.x, out.x);
    gather(s.y, out.y);
    gather(s.z, out.z);
    gather(s.i, out.i);
    gather(s.j, out.j);
    gather(s.k, out.k);
    gather(s.density, out.density);
    gather(s.extinction, out.extinction);
    gather(s.r, out.r);
    gather(s.g, out.g);
    gather(s.b, out.b);
    gather(s.nx, out.nx);
    gather(s.ny, out.ny);
    gather(s.nz, out.nz);
    return out;
}

std::vector<float> perspectivePathScale(const Camera& camera, const glm::dvec3& axis) {
    if (!camera.perspective()) return {};
    const int w = camera.width(), h = camera.height();
    std::vector<float> scale(std::size_t(w) * h);
    const double ref = std::abs(glm::dot(camera.view, axis));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Ray r = camera.ray(x + 0.5, y + 0.5);
            scale[std::size_t(y) * w + x] = float(ref / std::abs(glm::dot(r.dir, axis)));
        }
    return scale;
}

TransferTable::TransferTable(const TransferFunction& tf, int n) : n_(std::max(n, 2)) {
    if (tf.points.empty()) {
        v_.assign(std::size_t(n_) * 4, 0.0f);
        return;
    }
    lo_ = tf.points.front().value;
    const float hi = tf.points.back().value;
    const float step = hi > lo_ ? (hi - lo_) / float(n_ - 1) : 1.0f;
    inv_ = 1.0f / step;
    v_.resize(std::size_t(n_) * 4);
    for (int i = 0; i < n_; ++i) {
        const glm::vec4 c = tf.sample(lo_ + step * float(i));
        v_[std::size_t(i) * 4 + 0] = tf.extinctionFromOpacity(c.a);
        v_[std::size_t(i) * 4 + 1] = c.r;
        v_[std::size_t(i) * 4 + 2] = c.g;
        v_[std::size_t(i) * 4 + 3] = c.b;
    }
}

}  // namespace splat
