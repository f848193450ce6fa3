#pragma once
// The transfer function tabulated over density for per-pixel post-classification:
// extinction and colour at n uniformly spaced densities, linear interpolation between.
#include <algorithm>
#include <vector>

#include "splat/transfer.h"

namespace splat {

class TransferTable {
  public:
    TransferTable() = default;
    /// `offset`: the table is read at d - offset, i.e. lookup(x) is the transfer function at
    /// x + offset (the splatters' sheets hold f - b; offset = b).
    explicit TransferTable(const TransferFunction& tf, int n = 4096, float offset = 0.0f);
    /// Extinction per world unit and (non-premultiplied) colour at density d + offset.
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

}  // namespace splat
