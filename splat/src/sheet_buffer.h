#pragma once
// Sheet buffers, shared by both splatters. A sheet accumulates, per pixel of one tile,
// the weighted sums of the kernel pieces that fall into it: optical depth and emission
// (dvr, pre-classified; 4 channels) or the density integral (post-classified dvr, mip,
// xray; 1 channel). The splatters differ only in the weight a kernel piece gets (its
// whole footprint, or its slab section) and in which sheet it falls into.
#include <algorithm>
#include <array>
#include <vector>

#include "compositing.h"
#include "footprint/ellipse.h"
#include "splat/transfer.h"
#include "tile_binning.h"

namespace splat {

/// The transfer function tabulated over density for per-pixel post-classification:
/// extinction and colour at n uniformly spaced densities, linear interpolation between.
class TransferTable {
public:
    TransferTable() = default;
    TransferTable(const TransferFunction& tf, int n = 4096);
    /// Extinction per world unit and (non-premultiplied) colour at density d.
    void lookup(float d, float& rho, float& r, float& g, float& b) const {
        float t = (d - lo_) * inv_;
        t = std::clamp(t, 0.0f, float(n_ - 1));
        const int i = std::min(int(t), n_ - 2);
        const float f = t - float(i);
        const float* a = &v_[std::size_t(i) * 4];
        rho = a[0] + f * (a[4] - a[0]);
        r = a[1] + f * (a[5] - a[1]);
        g = a[2] + f * (a[6] - a[2]);
        b = a[3] + f * (a[7] - a[3]);
    }

private:
    float lo_ = 0, inv_ = 1;
    int n_ = 2;
    std::vector<float> v_;
};

/// How a sheet pixel becomes a compositing sample.
struct SheetModel {
    RenderMode mode = RenderMode::Dvr;
    Classification classification = Classification::Pre;
    const TransferTable* transfer = nullptr;  ///< post-classification
    int channels() const {
        return mode == RenderMode::Dvr && classification == Classification::Pre ? 4 : 1;
    }
};

template <int NCh>
class SheetBuffer {
public:
    /// A sheet for the tile whose top-left pixel is (ox, oy) and size w x h.
    SheetBuffer(int ox, int oy, int w, int h)
        : ox_(ox), oy_(oy), w_(w), h_(h), v_(std::size_t(NCh) * w * h, 0.0f) {
        clearDirty();
    }

    bool dirty() const { return dx0_ <= dx1_; }

    /// Adds values[c] * weight(r2, dx, dy) to every pixel of `rect` (image coordinates,
    /// inside this tile), where (dx, dy) is the pixel centre's offset from the splat
    /// centre (sx, sy) and r2 the squared kernel-space distance of its ray. Returns the
    /// number of pixels visited.
    template <class Weight>
    int splat(const float (&values)[NCh], float sx, float sy,
              const footprint::EllipticalFootprint& e, const PixelRect& rect, Weight&& weight) {
        const int x0 = rect.x0 - ox_, x1 = rect.x1 - ox_, y0 = rect.y0 - oy_, y1 = rect.y1 - oy_;
        dx0_ = std::min(dx0_, x0);
        dx1_ = std::max(dx1_, x1);
        dy0_ = std::min(dy0_, y0);
        dy1_ = std::max(dy1_, y1);
        const float fx0 = float(rect.x0) + 0.5f - sx;
        for (int y = y0; y <= y1; ++y) {
            const float dy = float(y + oy_) + 0.5f - sy;
            const float cyy = e.c * dy * dy, byy = 2.0f * e.b * dy;
            float* row = &v_[std::size_t(y) * w_];
            for (int x = x0; x <= x1; ++x) {
                const float dx = fx0 + float(x - x0);
                const float r2 = (e.a * dx + byy) * dx + cyy;
                const float wgt = weight(r2, dx, dy);
                for (int c = 0; c < NCh; ++c) row[std::size_t(c) * w_ * h_ + x] += values[c] * wgt;
            }
        }
        return (x1 - x0 + 1) * (y1 - y0 + 1);
    }

    /// Turns the dirty part of the sheet into samples composited into `acc`, clears it.
    /// `pathLength` is the world length of a ray's path through the sheet (for the mean
    /// density of post-classification and mip); `pathScale`, if given, scales it per pixel
    /// (perspective rays cross a sheet obliquely).
    void flush(TileAccumulator& acc, const SheetModel& model, float pathLength,
               const float* pathScale) {
        if (!dirty()) return;
        const std::size_t plane = std::size_t(w_) * h_;
        for (int y = dy0_; y <= dy1_; ++y)
            for (int x = dx0_; x <= dx1_; ++x) {
                const int p = y * w_ + x;
                float* v = &v_[p];
                const float len = pathScale ? pathLength * pathScale[p] : pathLength;
                if constexpr (NCh == 4) {
                    acc.composite(p, sampleFromOpticalDepth(v[0], v[plane], v[2 * plane],
                                                            v[3 * plane]));
                    v[plane] = v[2 * plane] = v[3 * plane] = 0.0f;
                } else if (model.mode == RenderMode::Dvr) {
                    float rho, r, g, b;
                    model.transfer->lookup(v[0] / len, rho, r, g, b);
                    const float alpha = -std::expm1(-rho * len);
                    acc.composite(p, {alpha, r * alpha, g * alpha, b * alpha});
                } else if (model.mode == RenderMode::Mip) {
                    acc.maximum(p, v[0] / len);
                } else {
                    acc.add(p, v[0]);
                }
                v[0] = 0.0f;
            }
        acc.updateOpacity(dx0_, dy0_, dx1_, dy1_);
        clearDirty();
    }

private:
    void clearDirty() {
        dx0_ = dy0_ = 1 << 30;
        dx1_ = dy1_ = -1;
    }
    int ox_, oy_, w_, h_;
    int dx0_, dy0_, dx1_, dy1_;
    std::vector<float> v_;  // NCh planes of w x h
};

}  // namespace splat
