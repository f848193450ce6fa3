#pragma once
// The reference ray caster's continuous fields, f(x) = sum_i d_i h(|S^-1 (x - x_i)|) and, for
// pre-classification, rho(x) and e(x) likewise (DESIGN: "Reconstructed fields"), evaluated
// exactly (up to the kernel table) at any index-space point:
//  - the splat list is scattered into a dense per-voxel grid (absent splats are 0), so a
//    field sample visits only the (2R + 1)^3 lattice points around it;
//  - a brick grid (8^3 voxels) marks bricks whose points lie within R of a non-zero voxel,
//    so rays can skip the space where the fields are exactly 0 (raySegments);
//  - h is tabulated in u^2 (65536 entries, linear interpolation; its error is far below
//    1e-6 of the peak, see tests/test_reference.cpp).
// Views through the volume (slices, MPR, CPR) evaluate the same fields.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "footprint/kernel.h"
#include "splat/classify.h"
#include "splat/error.h"
#include "splat/volume.h"

namespace splat {

constexpr int kBrick = 8;  // brick edge, voxels
constexpr int kLutSize = 1 << 16;

// h(u) tabulated over u^2 in [0, R^2].
class KernelLut {
  public:
    explicit KernelLut(const footprint::Kernel& kernel) {
        const double r = kernel.radius();
        r2Max_ = r * r;
        const double step = r2Max_ / kLutSize;
        inv_ = 1.0 / step;
        values_.resize(kLutSize + 2, 0.0f);
        for (int n = 0; n <= kLutSize; ++n) {
            const double u2 = std::min(n * step, r2Max_);
            values_[n] = n == kLutSize ? 0.0f : float(kernel(std::sqrt(u2)));
        }
    }
    double r2Max() const { return r2Max_; }
    float operator()(double u2) const {
        if (!(u2 < r2Max_)) return 0.0f;
        const double t = u2 * inv_;
        const int n = int(t);
        const float f = float(t - n);
        return values_[n] + f * (values_[n + 1] - values_[n]);
    }

  private:
    double r2Max_ = 0, inv_ = 0;
    std::vector<float> values_;
};

// Dense per-voxel values (C channels interleaved) plus the brick occupancy grid.
template <int C>
struct FieldGrid {
    glm::ivec3 dims{0};
    double radius = 0;
    std::vector<float> values;
    glm::ivec3 nb{0};
    std::vector<std::uint8_t> bricks;
    const KernelLut* lut = nullptr;

    std::size_t index(int i, int j, int k) const {
        return ((std::size_t(k) * dims.y + j) * dims.x + i) * C;
    }
    bool brick(int bx, int by, int bz) const {
        return bricks[(std::size_t(bz) * nb.y + by) * nb.x + bx] != 0;
    }

    // Sum of the C channels times h at index position p.
    void eval(const glm::dvec3& p, double out[C]) const {
        for (int c = 0; c < C; ++c) out[c] = 0.0;
        const double r = radius, r2 = lut->r2Max();
        const int i0 = std::max(0, int(std::ceil(p.x - r))),
                  i1 = std::min(dims.x - 1, int(std::floor(p.x + r)));
        const int j0 = std::max(0, int(std::ceil(p.y - r))),
                  j1 = std::min(dims.y - 1, int(std::floor(p.y + r)));
        const int k0 = std::max(0, int(std::ceil(p.z - r))),
                  k1 = std::min(dims.z - 1, int(std::floor(p.z + r)));
        if (i0 > i1 || j0 > j1 || k0 > k1) return;
        double dx2[64];
        const int ni = std::min(i1 - i0 + 1, 64);
        for (int n = 0; n < ni; ++n) {
            const double d = p.x - (i0 + n);
            dx2[n] = d * d;
        }
        for (int k = k0; k <= k1; ++k) {
            const double dz = p.z - k, dz2 = dz * dz;
            if (dz2 >= r2) continue;
            for (int j = j0; j <= j1; ++j) {
                const double dy = p.y - j, dyz = dy * dy + dz2;
                if (dyz >= r2) continue;
                const float* row = values.data() + index(i0, j, k);
                for (int n = 0; n < ni; ++n) {
                    const float w = (*lut)(dyz + dx2[n]);
                    if (w == 0.0f) continue;
                    for (int c = 0; c < C; ++c) out[c] += double(w) * double(row[n * C + c]);
                }
            }
        }
    }
};

template <int C>
FieldGrid<C> buildGrid(const Volume& volume, const SplatList& splats, const KernelLut& lut,
                       double radius, const std::array<const std::vector<float>*, C>& channels,
                       const std::vector<float>* alsoMark = nullptr) {
    FieldGrid<C> g;
    g.dims = volume.dims;
    g.radius = radius;
    g.lut = &lut;
    g.values.assign(volume.voxelCount() * C, 0.0f);
    // Brick b covers index positions [-R + b B, -R + (b + 1) B) on each axis.
    g.nb =
        glm::ivec3(glm::ceil((glm::dvec3(volume.dims) - 1.0 + 2.0 * radius) / double(kBrick))) + 1;
    g.bricks.assign(std::size_t(g.nb.x) * g.nb.y * g.nb.z, 0);
    for (const auto* ch : channels)
        if (ch->size() != splats.size())
            throw Error("reference: the splat list lacks the channels this mode needs");
    for (std::size_t s = 0; s < splats.size(); ++s) {
        const int i = splats.i[s], j = splats.j[s], k = splats.k[s];
        if (i >= volume.dims.x || j >= volume.dims.y || k >= volume.dims.z)
            throw Error("reference: splat index outside the volume");
        bool any = false;
        for (int c = 0; c < C; ++c) {
            const float v = (*channels[c])[s];
            g.values[g.index(i, j, k) + c] = v;
            any = any || v != 0.0f;
        }
        // Labels live outside the channels: their voxels' bricks are marked too.
        if (alsoMark && s < alsoMark->size() && (*alsoMark)[s] != 0.0f) any = true;
        if (!any) continue;
        // Points within R of voxel p lie in [p - R, p + R]: bricks floor(p / B) ..
        // floor((p + 2R) / B) in the brick frame that starts at -R.
        const glm::ivec3 p(i, j, k);
        glm::ivec3 lo, hi;
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::max(0, int(std::floor(p[a] / double(kBrick))));
            hi[a] = std::min(g.nb[a] - 1, int(std::floor((p[a] + 2.0 * radius) / kBrick)));
        }
        for (int bz = lo.z; bz <= hi.z; ++bz)
            for (int by = lo.y; by <= hi.y; ++by)
                for (int bx = lo.x; bx <= hi.x; ++bx)
                    g.bricks[(std::size_t(bz) * g.nb.y + by) * g.nb.x + bx] = 1;
    }
    return g;
}

struct Segment {
    double a, b;
};

// Cuts the line p0 + t v (index space, t world units) into the segments crossing marked
// bricks, within [tLo, tHi] and the volume bounds padded by R.
template <int C>
void raySegments(const FieldGrid<C>& g, const glm::dvec3& p0, const glm::dvec3& v, double tLo,
                 double tHi, std::vector<Segment>& out) {
    out.clear();
    const double r = g.radius;
    double tA = tLo, tB = tHi;
    for (int a = 0; a < 3; ++a) {
        const double lo = -r, hi = g.dims[a] - 1 + r;
        if (std::abs(v[a]) < 1e-300) {
            if (p0[a] < lo || p0[a] > hi) return;
            continue;
        }
        double t0 = (lo - p0[a]) / v[a], t1 = (hi - p0[a]) / v[a];
        if (t0 > t1) std::swap(t0, t1);
        tA = std::max(tA, t0);
        tB = std::min(tB, t1);
    }
    if (!(tA < tB)) return;
    const double origin = -r;
    const glm::dvec3 pa = p0 + tA * v;
    glm::ivec3 cell, step;
    glm::dvec3 tMax, tDelta;
    for (int a = 0; a < 3; ++a) {
        cell[a] = std::clamp(int(std::floor((pa[a] - origin) / kBrick)), 0, g.nb[a] - 1);
        if (v[a] > 1e-300) {
            step[a] = 1;
            tMax[a] = (origin + (cell[a] + 1.0) * kBrick - p0[a]) / v[a];
            tDelta[a] = kBrick / v[a];
        } else if (v[a] < -1e-300) {
            step[a] = -1;
            tMax[a] = (origin + cell[a] * double(kBrick) - p0[a]) / v[a];
            tDelta[a] = -kBrick / v[a];
        } else {
            step[a] = 0;
            tMax[a] = std::numeric_limits<double>::infinity();
            tDelta[a] = tMax[a];
        }
    }
    double t = tA;
    while (t < tB) {
        const int axis = tMax.x <= tMax.y ? (tMax.x <= tMax.z ? 0 : 2) : (tMax.y <= tMax.z ? 1 : 2);
        const double tn = std::min(tMax[axis], tB);
        if (tn > t && g.brick(cell.x, cell.y, cell.z)) {
            if (!out.empty() && out.back().b == t)
                out.back().b = tn;
            else
                out.push_back({t, tn});
        }
        t = std::max(t, tn);
        cell[axis] += step[axis];
        tMax[axis] += tDelta[axis];
        if (cell[axis] < 0 || cell[axis] >= g.nb[axis]) break;
    }
}

/// Segmentation labels for the reference: the shown label of every voxel and colour and
/// extinction (a) per label; a point takes the label of its nearest voxel.
struct LabelLookup {
    glm::ivec3 dims{0};
    const std::vector<std::uint16_t>* shown = nullptr;
    const std::vector<glm::vec4>* table = nullptr;
    /// Adds the label's (rho, e) at index-space point p to out[0..3].
    void add(const glm::dvec3& p, float* out) const {
        const glm::ivec3 q(glm::round(p));
        if (q.x < 0 || q.y < 0 || q.z < 0 || q.x >= dims.x || q.y >= dims.y || q.z >= dims.z)
            return;
        const std::size_t label =
            (*shown)[(std::size_t(q.z) * dims.y + std::size_t(q.y)) * dims.x + std::size_t(q.x)];
        if (label == 0 || label >= table->size()) return;
        const glm::vec4 c = (*table)[label];
        out[0] += c.a;
        out[1] += c.r * c.a;
        out[2] += c.g * c.a;
        out[3] += c.b * c.a;
    }
};

/// Which fields a ReferenceField holds.
enum class FieldLayout {
    Density,          ///< f (one channel): post-classified dvr, mip, xray, iso, views
    Emission,         ///< rho, e_r, e_g, e_b: pre-classified dvr
    DensityGradient,  ///< f and the reconstructed central-difference gradient g_x, g_y, g_z
};

/// The fields of one classified scene (see FieldLayout). Not copyable (the grids point at
/// the kernel table).
class ReferenceField {
  public:
    ReferenceField(const Volume& volume, const SplatList& splats, const footprint::Kernel& kernel,
                   FieldLayout layout);
    ReferenceField(const ReferenceField&) = delete;
    ReferenceField& operator=(const ReferenceField&) = delete;

    FieldLayout layout() const { return layout_; }
    bool fourChannels() const { return layout_ != FieldLayout::Density; }
    /// f at a world position (Density and DensityGradient layouts): b + the grid's f - b.
    double density(const Volume& volume, const glm::dvec3& world) const {
        double v[4];
        const glm::dvec3 p = (world - volume.origin) / volume.spacing;
        if (fourChannels()) {
            grid4_.eval(p, v);
        } else {
            grid1_.eval(p, v);
        }
        return v[0] + double(background_);
    }
    const FieldGrid<4>& grid4() const { return grid4_; }
    const FieldGrid<1>& grid1() const { return grid1_; }
    double radius() const { return radius_; }

  private:
    KernelLut lut_;
    double radius_;
    FieldLayout layout_;
    float background_ = 0.0f;  ///< b (the grids hold d_i - b, SplatList::background)
    FieldGrid<4> grid4_;
    FieldGrid<1> grid1_;
};

}  // namespace splat
