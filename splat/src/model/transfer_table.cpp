// The post-classification transfer table (see transfer_table.h).
#include "model/transfer_table.h"

namespace splat {

TransferTable::TransferTable(const TransferFunction& tf, int n, float offset)
    : n_(std::max(n, 2)) {
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
    lo_ -= offset;
}

}  // namespace splat
