#include "footprint/slab_table.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "quadrature.h"

namespace footprint {

SlabTable::SlabTable(const Kernel& kernel, int radialResolution, int depthResolution)
    : kernel_(kernel),
      footprint_(kernel),
      nr_(radialResolution),
      nz_(depthResolution),
      closed_(GaussianSlab::of(kernel)) {
    if (nr_ < 2 || nr_ > (1 << 14) || nz_ < 2 || nz_ > (1 << 14))
        throw std::invalid_argument("SlabTable: resolutions must be in [2, 2^14], got " +
                                    std::to_string(nr_) + " x " + std::to_string(nz_));
    const double R = kernel_.radius();
    stride_ = nz_ + 2;
    // F on (nr + 2) x (nz + 2), z fastest (guards for + 1); stored interleaved below.
    std::vector<float> grid(std::size_t(nr_ + 2) * stride_, 0.0f);
    const double r2Step = R * R / nr_, zStep = 2.0 * R / nz_;
    const Kernel& k = kernel_;
    const double s = k.sigma();
    const bool bspline = k.type() == KernelType::CubicBSpline;
    std::vector<double> c(nz_ + 1);
    for (int i = 0; i <= nr_; ++i) {
        float* row = grid.data() + std::size_t(i) * stride_;
        const double r2 = i * r2Step;
        const double L = i < nr_ ? std::sqrt(std::max(0.0, R * R - r2)) : 0.0;
        double total = 0;
        if (L > 0) {
            const double zk = (bspline && r2 < s * s) ? std::sqrt(s * s - r2) : -2 * R;
            auto f = [&](double z) { return k(std::sqrt(r2 + z * z)); };
            const double tol = 1e-15 * k(0.0) * R;
            c[0] = 0;
            for (int j = 1; j <= nz_; ++j) {
                const double z0 = std::max(-L, -R + (j - 1) * zStep);
                const double z1 = std::min(L, j == nz_ ? R : -R + j * zStep);
                total += detail::integrateSplit(f, z0, z1, {-zk, 0.0, zk}, tol);
                c[j] = total;
            }
        }
        if (total > 0) {
            for (int j = 0; j < nz_; ++j) row[j] = float(std::min(1.0, c[j] / total));
        } else {
            // r = R: the kernel's chord shrinks to a point at z = 0 (a step).
            for (int j = 0; j < nz_; ++j) {
                const double z = -R + j * zStep;
                row[j] = z > 1e-12 * R ? 1.0f : (z < -1e-12 * R ? 0.0f : 0.5f);
            }
        }
        row[nz_] = 1.0f;
        row[nz_ + 1] = 1.0f;
    }
    std::copy_n(grid.data() + std::size_t(nr_) * stride_, stride_,
                grid.data() + std::size_t(nr_ + 1) * stride_);
    values_.resize(std::size_t(nr_ + 1) * stride_ * 2);
    for (int i = 0; i <= nr_; ++i)
        for (int j = 0; j < stride_; ++j) {
            const std::size_t k = std::size_t(i) * stride_ + j;
            values_[2 * k] = grid[k];
            values_[2 * k + 1] = grid[k + stride_];
        }
    r2Max_ = float(R * R);
    invR2Step_ = float(nr_ / (R * R));
    invZStep_ = float(nz_ / (2.0 * R));
    zMin_ = float(-R);
    nrf_ = float(nr_);
    nzf_ = float(nz_);
    // Saturation bounds. A lookup in grid cell (i, j) reads rows i, i + 1 at columns j,
    // j + 1 (j = floor of the grid depth, clamped to [0, nz]). Row i reads exactly 0 below
    // column lo[i] and exactly 1 from column hi[i] on; the bounds hold for every row at or
    // beyond i (suffix min / max), with one column of margin for the rounding of the depth.
    auto lo = [&](int i) {
        const float* row = grid.data() + std::size_t(i) * stride_;
        int j = 0;
        while (j < stride_ && row[j] == 0.0f) ++j;
        return j;
    };
    auto hi = [&](int i) {
        const float* row = grid.data() + std::size_t(i) * stride_;
        int j = stride_;
        while (j > 0 && row[j - 1] == 1.0f) --j;
        return j;
    };
    saturation_.resize(std::size_t(nr_) + 1);
    int zeroCols = stride_, oneCol = 0;
    for (int i = nr_; i >= 0; --i) {
        zeroCols = std::min({zeroCols, lo(i), lo(i + 1)});
        oneCol = std::max({oneCol, hi(i), hi(i + 1)});
        // Cell j is all 0 for j + 1 < zeroCols, i.e. grid depth < zeroCols - 1; all 1 for
        // j >= oneCol, i.e. grid depth >= oneCol. Margin: one column each.
        // Beyond the grid the depth clamps to its ends, whose F is exactly 0 (z <= -R) and 1
        // (z >= R; half a step of margin, the scaled depth may round below nz).
        const double zStepD = 2.0 * R / nz_;
        saturation_[std::size_t(i)].zeroBelow =
            std::max(zMin_, zeroCols >= 2 ? float(-R + (zeroCols - 2) * zStepD) : -HUGE_VALF);
        saturation_[std::size_t(i)].oneAbove =
            std::min(float(R + 0.5 * zStepD), float(-R + (oneCol + 1) * zStepD));
    }
}

double SlabTable::exact(double r, double z) const {
    r = std::abs(r);
    const double R = kernel_.radius();
    if (!(r < R) || std::isnan(z)) return 0.0;
    const double r2 = r * r;
    const double L = std::sqrt((R - r) * (R + r));
    const Kernel& k = kernel_;
    const double s = k.sigma();
    const double zk =
        (k.type() == KernelType::CubicBSpline && r < s) ? std::sqrt(s * s - r2) : -2 * R;
    auto f = [&](double t) { return k(std::sqrt(r2 + t * t)); };
    return detail::integrateSplit(f, -L, std::min(z, L), {-zk, 0.0, zk}, 1e-14 * k(0.0) * R);
}

}  // namespace footprint
