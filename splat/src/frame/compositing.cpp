// The shared compositing stage (see compositing.h).
#include "compositing.h"

#include <algorithm>

#include "splat/error.h"

namespace splat {

namespace {
constexpr int kBlock = 4;  // early-termination granularity, pixels (64 blocks per 32x32 tile)
}

TileAccumulator::TileAccumulator(int width, int height, CompositeOrder order,
                                 double earlyTermination, bool surface)
    : w_(width),
      h_(height),
      order_(order),
      terminates_(order == CompositeOrder::FrontToBack && earlyTermination > 0),
      threshold_(float(1.0 - earlyTermination)),
      blocksX_((width + kBlock - 1) / kBlock),
      blocksY_((height + kBlock - 1) / kBlock) {
    if (blocksX_ * blocksY_ > 64) throw Error("tile size above 64 pixels is not supported");
    allBlocks_ = blocksX_ * blocksY_ == 64 ? ~std::uint64_t(0)
                                           : (std::uint64_t(1) << (blocksX_ * blocksY_)) - 1;
    const std::size_t n = std::size_t(w_) * h_;
    r_.assign(n, 0.0f);
    g_.assign(n, 0.0f);
    b_.assign(n, 0.0f);
    a_.assign(n, 0.0f);
    if (surface) {
        prev_.assign(n, 0.0f);
        pos_.assign(n, -1.0f);
    }
}

void TileAccumulator::resolvePositions(Image& image, int ox, int oy) const {
    for (int y = 0; y < h_; ++y)
        for (int x = 0; x < w_; ++x) {
            const int p = y * w_ + x;
            const bool hit = !pos_.empty() && a_[p] >= 1.0f;
            image.at(ox + x, oy + y) =
                glm::vec4(hit ? pos_[p] : 0.0f, 0.0f, 0.0f, hit ? 1.0f : 0.0f);
        }
}

bool TileAccumulator::rectOpaque(int x0, int y0, int x1, int y1) const {
    if (!terminates_) return false;
    for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
        for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx)
            if (!(opaqueBlocks_ >> (by * blocksX_ + bx) & 1)) return false;
    return true;
}

void TileAccumulator::updateOpacity(int x0, int y0, int x1, int y1) {
    if (!terminates_) return;
    for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
        for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx) {
            const std::uint64_t bit = std::uint64_t(1) << (by * blocksX_ + bx);
            if (opaqueBlocks_ & bit) continue;
            bool opaque = true;
            const int ye = std::min(h_, (by + 1) * kBlock), xe = std::min(w_, (bx + 1) * kBlock);
            for (int y = by * kBlock; y < ye && opaque; ++y)
                for (int x = bx * kBlock; x < xe; ++x)
                    if (a_[y * w_ + x] < threshold_) {
                        opaque = false;
                        break;
                    }
            if (opaque) opaqueBlocks_ |= bit;
        }
}

void TileAccumulator::resolve(Image& image, int ox, int oy, RenderMode mode) const {
    for (int y = 0; y < h_; ++y)
        for (int x = 0; x < w_; ++x) {
            const int p = y * w_ + x;
            image.at(ox + x, oy + y) = mode == RenderMode::Dvr || mode == RenderMode::Iso
                                           ? glm::vec4(r_[p], g_[p], b_[p], a_[p])
                                           : glm::vec4(r_[p], r_[p], r_[p], 1.0f);
        }
}

void applyBackground(Image& image, RenderMode mode, const glm::vec4& bg) {
    if (mode != RenderMode::Dvr && mode != RenderMode::Iso) return;
    for (glm::vec4& out : image.pixels) out = out + (1.0f - out.a) * bg;
}

}  // namespace splat
