#pragma once
// Sheet buffers, shared by both splatters. A sheet accumulates, per pixel of one tile,
// the weighted sums of the kernel pieces that fall into it, in the channels of the
// frame's compositing policy (compositing.h): optical depth and emission (pre-classified
// dvr) or the density integral (post-classified dvr, mip, xray). The splatters differ only
// in the weight a kernel piece gets (its whole footprint, or its slab section) and in which
// sheet it falls into (splat/src/splatters/).
#include <algorithm>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "footprint/ellipse.h"
#include "frame/compositing.h"
#include "frame/tile_binning.h"

namespace splat {

template <int NCh>
class SheetBuffer {
  public:
    /// A sheet for the tile whose top-left pixel is (ox, oy) and size w x h. Rows are
    /// padded to a multiple of 8 floats so that vector loops may run past the tile edge.
    SheetBuffer(int ox, int oy, int w, int h)
        : ox_(ox),
          oy_(oy),
          w_(w),
          h_(h),
          stride_((w + 7) & ~7),
          plane_(std::size_t(stride_) * h + kPlanePad),
          v_(std::size_t(NCh) * plane_ + 8, 0.0f) {
        clearDirty();
    }

    bool dirty() const { return dx0_ <= dx1_; }
    /// The tile-local pixels that may have been written, [x0, x1] x [y0, y1].
    void dirtyBounds(int& x0, int& y0, int& x1, int& y1) const {
        x0 = dx0_;
        y0 = dy0_;
        x1 = dx1_;
        y1 = dy1_;
    }

    /// Re-targets a clean sheet to the tile at (ox, oy) of size w x h, no larger than the
    /// tile it was made for (the streaming splatters reuse one sheet per thread for every
    /// tile instead of clearing a fresh one per tile and chunk).
    void moveTo(int ox, int oy, int w, int h) {
        if (((w + 7) & ~7) > stride_ || std::size_t(stride_) * h + kPlanePad > plane_)
            throw std::logic_error("SheetBuffer::moveTo: tile larger than the sheet");
        ox_ = ox;
        oy_ = oy;
        w_ = w;
        h_ = h;
    }

    /// Clears whatever the sheet holds without compositing it.
    void discard() {
        if (!dirty()) return;
        for (int c = 0; c < NCh; ++c)
            for (int y = dy0_; y <= dy1_; ++y) {
                float* row = &v_[c * plane_ + std::size_t(y) * stride_];
                std::fill(row + dx0_, row + dx1_ + 1, 0.0f);
            }
        clearDirty();
    }

    /// Adds values[c] * weight(r2, dx, dy) to every pixel of `rect` (image coordinates,
    /// inside this tile), where (dx, dy) is the pixel centre's offset from the splat
    /// centre (sx, sy) and r2 the squared kernel-space distance of its ray
    /// (EllipticalFootprint::r2). The scalar loop of both splatters; returns the number of
    /// pixels visited.
    template <class Weight>
    int splat(const float (&values)[NCh], float sx, float sy,
              const footprint::EllipticalFootprint& e, const PixelRect& rect, Weight&& weight) {
        const int x0 = rect.x0 - ox_, x1 = rect.x1 - ox_, y0 = rect.y0 - oy_, y1 = rect.y1 - oy_;
        markDirty(x0, x1, y0, y1);
        const float fx0 = float(rect.x0) + 0.5f - sx;
        for (int y = y0; y <= y1; ++y) {
            const float dy = float(y + oy_) + 0.5f - sy;
            const float shift = e.beta * dy, gyy = e.gamma * dy * dy;
            float* row = &v_[std::size_t(y) * stride_];
            for (int x = x0; x <= x1; ++x) {
                const float dx = fx0 + float(x - x0);
                const float q = dx + shift;
                const float r2 = e.a * q * q + gyy;
                const float wgt = weight(r2, dx, dy);
                if constexpr (NCh == kLabelChannels) {
                    for (int c = 0; c < 4; ++c) row[c * plane_ + x] += values[c] * wgt;
                    const float w = values[4] * wgt;
                    if (w > row[4 * plane_ + x]) {
                        row[4 * plane_ + x] = w;
                        row[5 * plane_ + x] = values[5];
                    }
                } else {
                    for (int c = 0; c < NCh; ++c) row[c * plane_ + x] += values[c] * wgt;
                }
            }
        }
        return (x1 - x0 + 1) * (y1 - y0 + 1);
    }

    /// Turns the dirty part of the sheet into samples composited into `acc` by `policy`,
    /// and clears it. `pathLength` is the world length of a ray's path through the sheet;
    /// `pathScale`, if given, scales it per pixel (perspective rays cross a sheet
    /// obliquely).
    template <class Policy>
    void flush(TileAccumulator& acc, const Policy& policy, float pathLength,
               const float* pathScale) {
        if (!dirty()) return;
        const int xe = std::min(dx1_, w_ - 1);
        for (int y = dy0_; y <= dy1_; ++y) {
            if constexpr (std::is_same_v<Policy, DvrPrePolicy>) {
                const float* v = &v_[std::size_t(y) * stride_ + dx0_];
                acc.compositeOpticalDepths(y * w_ + dx0_, xe - dx0_ + 1, v, v + plane_,
                                           v + 2 * plane_, v + 3 * plane_);
            } else {
                for (int x = dx0_; x <= xe; ++x) {
                    const int p = y * w_ + x;
                    const float len = pathScale ? pathLength * pathScale[p] : pathLength;
                    policy(acc, p, &v_[std::size_t(y) * stride_ + x], plane_, len);
                }
            }
            for (int c = 0; c < NCh; ++c) {
                float* row = &v_[c * plane_ + std::size_t(y) * stride_];
                std::fill(row + dx0_, row + dx1_ + 1, 0.0f);
            }
        }
        acc.updateOpacity(dx0_, dy0_, xe, dy1_);
        clearDirty();
    }

    /// Row y of channel c (tile-local), for the splatters' vector loops.
    float* row(int c, int y) { return &v_[c * plane_ + std::size_t(y) * stride_]; }
    int originX() const { return ox_; }
    int originY() const { return oy_; }
    /// Records that tile-local pixels [x0, x1] x [y0, y1] may have been written.
    void markDirty(int x0, int x1, int y0, int y1) {
        dx0_ = std::min(dx0_, x0);
        dx1_ = std::max(dx1_, x1);
        dy0_ = std::min(dy0_, y0);
        dy1_ = std::max(dy1_, y1);
    }

  private:
    void clearDirty() {
        dx0_ = dy0_ = 1 << 30;
        dx1_ = dy1_ = -1;
    }
    // Channel planes of a 32 x 32 tile would be exactly 4 KiB apart, and loads of one plane
    // would then falsely depend on stores to the plane before (4K aliasing): pad them.
    static constexpr std::size_t kPlanePad = 24;
    int ox_, oy_, w_, h_, stride_;
    std::size_t plane_;
    int dx0_, dy0_, dx1_, dy1_;
    std::vector<float> v_;  // NCh planes of stride x h
};

}  // namespace splat
