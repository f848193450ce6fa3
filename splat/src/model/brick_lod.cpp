// Level of detail per brick and view (see brick_lod.h).
#include "model/brick_lod.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "model/level_of_detail.h"
#include "splat/classify.h"

namespace splat {

namespace {

/// Level-l voxels along one axis of brick `b`, on a level grid of `n` voxels.
int voxelsInBrick(int b, int l, int n) {
    const int side = kLodBrick >> l;
    return std::max(0, std::min((b + 1) * side, n) - b * side);
}

/// Per brick, the sum over the level-(l - 1) voxels of occupied level-l cells of (value -
/// trilinear interpolation of the level-l means)^2 (voxels without a splat count as 0, and
/// so does the field outside the grid). Summed per coarse slice, then slice by slice in
/// order: the same sums on any thread count.
std::vector<double> levelDetailSums(const SplatList& fine, const glm::ivec3& fd,
                                    const SplatList& coarse, const glm::ivec3& cd, int l,
                                    const glm::ivec3& bricks) {
    std::vector<float> grid(std::size_t(cd.x) * cd.y * cd.z, 0.0f);
    for (std::size_t q = 0; q < coarse.size(); ++q)
        grid[(std::size_t(coarse.k[q]) * cd.y + coarse.j[q]) * cd.x + coarse.i[q]] =
            coarse.densityOf(q);
    auto at = [&](int i, int j, int k) {
        if (i < 0 || j < 0 || k < 0 || i >= cd.x || j >= cd.y || k >= cd.z) return 0.0f;
        return grid[(std::size_t(k) * cd.y + j) * cd.x + i];
    };
    // Fine voxel n sits at coarse index (n - 0.5) / 2 (coarserGrid).
    auto predict = [&](int fi, int fj, int fk) {
        const int i0 = (fi - 1) >> 1, j0 = (fj - 1) >> 1, k0 = (fk - 1) >> 1;
        const float ti = fi & 1 ? 0.25f : 0.75f, tj = fj & 1 ? 0.25f : 0.75f,
                    tk = fk & 1 ? 0.25f : 0.75f;
        float v = 0.0f;
        for (int c = 0; c < 8; ++c) {
            const float w = (c & 1 ? ti : 1.0f - ti) * (c & 2 ? tj : 1.0f - tj) *
                            (c & 4 ? tk : 1.0f - tk);
            v += w * at(i0 + (c & 1), j0 + (c >> 1 & 1), k0 + (c >> 2 & 1));
        }
        return v;
    };
    const std::size_t ny = std::size_t(fd.y);
    std::vector<std::uint32_t> row(ny * std::size_t(fd.z) + 1, 0);
    for (std::size_t q = 0; q < fine.size(); ++q) ++row[std::size_t(fine.k[q]) * ny + fine.j[q] + 1];
    for (std::size_t r = 1; r < row.size(); ++r) row[r] += row[r - 1];

    const std::size_t layer = std::size_t(bricks.x) * bricks.y;
    std::vector<double> slices(std::size_t(cd.z) * layer, 0.0);
    const int shift = l - 1;  // level-(l - 1) index to level-0 index
    tbb::parallel_for(0, cd.z, [&](int K) {
        double* sums = slices.data() + std::size_t(K) * layer;
        std::vector<float> value(std::size_t(cd.x) * 8);
        std::vector<std::uint8_t> mask(std::size_t(cd.x));
        for (int J = 0; J < cd.y; ++J) {
            std::fill(mask.begin(), mask.end(), std::uint8_t(0));
            for (int k = 2 * K; k < std::min(2 * K + 2, fd.z); ++k)
                for (int j = 2 * J; j < std::min(2 * J + 2, fd.y); ++j) {
                    const std::size_t r = std::size_t(k) * ny + std::size_t(j);
                    for (std::size_t q = row[r]; q < row[r + 1]; ++q) {
                        const int i = fine.i[q], bit = (i & 1) | (j & 1) << 1 | (k & 1) << 2;
                        value[std::size_t(i / 2) * 8 + bit] = fine.densityOf(q);
                        mask[std::size_t(i / 2)] |= std::uint8_t(1 << bit);
                    }
                }
            const std::size_t brickRow = std::size_t((2 * J << shift) / kLodBrick) * bricks.x;
            for (int I = 0; I < cd.x; ++I) {
                const std::uint8_t m = mask[std::size_t(I)];
                if (!m) continue;
                for (int bit = 0; bit < 8; ++bit) {
                    const int fi = 2 * I + (bit & 1), fj = 2 * J + (bit >> 1 & 1),
                              fk = 2 * K + (bit >> 2 & 1);
                    if (fi >= fd.x || fj >= fd.y || fk >= fd.z) continue;
                    const float v = m & (1 << bit) ? value[std::size_t(I) * 8 + bit] : 0.0f;
                    const double res = double(v - predict(fi, fj, fk));
                    sums[brickRow + std::size_t((fi << shift) / kLodBrick)] += res * res;
                }
            }
        }
    });
    std::vector<double> total(std::size_t(bricks.z) * layer, 0.0);
    for (int K = 0; K < cd.z; ++K) {
        const std::size_t bk = std::size_t((2 * K << shift) / kLodBrick);
        for (std::size_t b = 0; b < layer; ++b)
            total[bk * layer + b] += slices[std::size_t(K) * layer + b];
    }
    return total;
}

/// Seams (brick_lod.h, 3.): lowers a brick to a face-neighbour's finer level wherever the
/// field on their shared face is above `tolerance`, until no such face is left.
void relaxSeams(const BrickDetail& d, const glm::ivec3& bricks, double tolerance,
                std::vector<std::uint8_t>& level) {
    for (bool changed = true; changed;) {
        changed = false;
        for (int bk = 0; bk < bricks.z; ++bk)
            for (int bj = 0; bj < bricks.y; ++bj)
                for (int bi = 0; bi < bricks.x; ++bi) {
                    const std::size_t b = (std::size_t(bk) * bricks.y + bj) * bricks.x + bi;
                    if (!d.occupied[b] || level[b] == 0) continue;
                    const int at[3] = {bi, bj, bk}, n[3] = {bricks.x, bricks.y, bricks.z};
                    const std::size_t stride[3] = {1, std::size_t(bricks.x),
                                                   std::size_t(bricks.x) * bricks.y};
                    for (int a = 0; a < 3; ++a)
                        for (int side = 0; side < 2; ++side) {
                            const int to = at[a] + (side ? 1 : -1);
                            if (to < 0 || to >= n[a]) continue;
                            const std::size_t m = side ? b + stride[a] : b - stride[a];
                            if (!d.occupied[m] || level[m] >= level[b]) continue;
                            const double f = std::max(d.face[6 * b + 2 * a + side],
                                                      d.face[6 * m + 2 * a + 1 - side]);
                            if (f > tolerance) {
                                level[b] = level[m];
                                changed = true;
                            }
                        }
                }
    }
}

}  // namespace

BrickDetail brickDetail(const std::vector<const SplatList*>& levels,
                        const std::vector<glm::ivec3>& dims) {
    BrickDetail d;
    d.bricks = (dims[0] + (kLodBrick - 1)) / kLodBrick;
    const SplatList& l0 = *levels[0];
    double s2 = 0;
    for (std::size_t q = 0; q < l0.size(); ++q) s2 += double(l0.densityOf(q)) * l0.densityOf(q);
    d.fieldRms = std::sqrt(s2 / double(std::max<std::size_t>(l0.size(), 1)));
    d.occupied.assign(d.count(), 0);
    std::vector<double> face(6 * d.count(), 0.0);
    for (std::size_t q = 0; q < l0.size(); ++q) {
        const int i = l0.i[q], j = l0.j[q], k = l0.k[q];
        const std::size_t b = d.brick(i, j, k);
        d.occupied[b] = 1;
        const double v2 = double(l0.densityOf(q)) * l0.densityOf(q);
        const int at[3] = {i % kLodBrick, j % kLodBrick, k % kLodBrick};
        const int n[3] = {dims[0].x, dims[0].y, dims[0].z};
        const int idx[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
            if (at[a] == 0) face[6 * b + 2 * a] += v2;
            if (at[a] == kLodBrick - 1 || idx[a] == n[a] - 1) face[6 * b + 2 * a + 1] += v2;
        }
    }
    d.face.assign(face.size(), 0.0f);
    for (int bk = 0; bk < d.bricks.z; ++bk)
        for (int bj = 0; bj < d.bricks.y; ++bj)
            for (int bi = 0; bi < d.bricks.x; ++bi) {
                const std::size_t b = (std::size_t(bk) * d.bricks.y + bj) * d.bricks.x + bi;
                const double w[3] = {double(voxelsInBrick(bi, 0, dims[0].x)),
                                     double(voxelsInBrick(bj, 0, dims[0].y)),
                                     double(voxelsInBrick(bk, 0, dims[0].z))};
                for (int a = 0; a < 3; ++a) {
                    const double layer = w[(a + 1) % 3] * w[(a + 2) % 3];
                    for (int side = 0; side < 2; ++side)
                        d.face[6 * b + 2 * a + side] =
                            float(std::sqrt(face[6 * b + 2 * a + side] / std::max(layer, 1.0)));
                }
            }
    d.levels = std::min(int(levels.size()) - 1, kLodBrickMaxLevel);
    const std::size_t n = d.count();
    d.detail.assign(std::size_t(std::max(d.levels, 0)) * n, 0.0f);
    std::vector<double> acc(n, 0.0);
    for (int l = 1; l <= d.levels; ++l) {
        const std::vector<double> sums = levelDetailSums(*levels[std::size_t(l - 1)],
                                                         dims[std::size_t(l - 1)],
                                                         *levels[std::size_t(l)],
                                                         dims[std::size_t(l)], l, d.bricks);
        const glm::ivec3 fd = dims[std::size_t(l - 1)];
        for (int bk = 0; bk < d.bricks.z; ++bk)
            for (int bj = 0; bj < d.bricks.y; ++bj)
                for (int bi = 0; bi < d.bricks.x; ++bi) {
                    const std::size_t b = (std::size_t(bk) * d.bricks.y + bj) * d.bricks.x + bi;
                    const double voxels = double(voxelsInBrick(bi, l - 1, fd.x)) *
                                          voxelsInBrick(bj, l - 1, fd.y) *
                                          voxelsInBrick(bk, l - 1, fd.z);
                    if (voxels > 0) acc[b] += sums[b] / voxels;
                    d.detail[std::size_t(l - 1) * n + b] = float(std::sqrt(acc[b]));
                }
    }
    return d;
}

std::vector<std::uint8_t> brickLevels(const Camera& camera, const glm::dvec3& origin,
                                      const glm::dvec3& spacing, const glm::ivec3& dims,
                                      double sigma, double kernelVariance, int maxLevel,
                                      const BrickDetail* detail) {
    const glm::ivec3 bricks = (dims + (kLodBrick - 1)) / kLodBrick;
    maxLevel = std::min(maxLevel, kLodBrickMaxLevel);
    const double voxel = std::max(spacing.x, std::max(spacing.y, spacing.z));
    const int orthographic =
        camera.perspective() ? 0 : lodAutoLevel(voxel / camera.pixelSize, sigma, kernelVariance, maxLevel);
    const double tol = kLodDetail;
    std::vector<std::uint8_t> level(std::size_t(bricks.x) * bricks.y * bricks.z, 0);
    const std::size_t n = level.size();
    for (int bk = 0; bk < bricks.z; ++bk)
        for (int bj = 0; bj < bricks.y; ++bj)
            for (int bi = 0; bi < bricks.x; ++bi) {
                const std::size_t b = (std::size_t(bk) * bricks.y + bj) * bricks.x + bi;
                int L = orthographic;
                if (camera.perspective()) {
                    // Nearest depth of the brick's box (its voxels' cells, half a voxel out).
                    const glm::dvec3 lo = glm::dvec3(bi, bj, bk) * double(kLodBrick) - 0.5;
                    const glm::dvec3 hi =
                        glm::min(glm::dvec3(bi + 1, bj + 1, bk + 1) * double(kLodBrick),
                                 glm::dvec3(dims)) -
                        0.5;
                    double nearest = INFINITY;
                    for (int c = 0; c < 8; ++c) {
                        const glm::dvec3 idx(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y,
                                             c & 4 ? hi.z : lo.z);
                        nearest = std::min(
                            nearest, glm::dot(origin + spacing * idx - camera.eye, camera.view));
                    }
                    L = nearest > 0 ? lodAutoLevel(voxel / (camera.pixelSize * nearest /
                                                            camera.focal),
                                                   sigma, kernelVariance, maxLevel)
                                    : 0;
                }
                if (detail) {
                    L = std::min(L, detail->levels);
                    while (L > 0 &&
                           double(detail->detail[std::size_t(L - 1) * n + b]) >
                               tol * detail->fieldRms)
                        --L;
                }
                level[b] = std::uint8_t(L);
            }
    if (detail) relaxSeams(*detail, bricks, tol * detail->fieldRms, level);
    return level;
}

SplatList splatsOfBricks(const SplatList& s, int L, const std::vector<std::uint8_t>& levels,
                         const glm::ivec3& bricks) {
    std::vector<std::uint32_t> keep;
    for (std::size_t q = 0; q < s.size(); ++q) {
        const std::size_t b =
            (std::size_t((int(s.k[q]) << L) / kLodBrick) * bricks.y +
             std::size_t((int(s.j[q]) << L) / kLodBrick)) *
                bricks.x +
            std::size_t((int(s.i[q]) << L) / kLodBrick);
        if (levels[b] == L) keep.push_back(std::uint32_t(q));
    }
    SplatList out;
    out.origin = s.origin;
    out.spacing = s.spacing;
    out.background = s.background;
    out.palette = s.palette;
    out.paletteDensity = s.paletteDensity;
    out.gradientScale = s.gradientScale;
    out.voxels = s.voxels;
    auto pick = [&](const auto& from, auto& to) {
        if (from.empty()) return;
        to.resize(keep.size());
        for (std::size_t n = 0; n < keep.size(); ++n) to[n] = from[keep[n]];
    };
    pick(s.i, out.i);
    pick(s.j, out.j);
    pick(s.k, out.k);
    pick(s.density, out.density);
    pick(s.extinction, out.extinction);
    pick(s.r, out.r);
    pick(s.g, out.g);
    pick(s.b, out.b);
    pick(s.emissionIndex, out.emissionIndex);
    pick(s.nx, out.nx);
    pick(s.ny, out.ny);
    pick(s.nz, out.nz);
    pick(s.gx, out.gx);
    pick(s.gy, out.gy);
    pick(s.gz, out.gz);
    pick(s.label, out.label);
    return out;
}

}  // namespace splat
