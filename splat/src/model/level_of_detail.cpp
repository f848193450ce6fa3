// The next (2x) level of a splat list (see level_of_detail.h).
#include "model/level_of_detail.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace splat {

Volume coarserGrid(const Volume& fine) {
    Volume v;
    v.dims = (fine.dims + 1) / 2;
    v.spacing = 2.0 * fine.spacing;
    v.origin = fine.origin + 0.5 * fine.spacing;
    v.direction = fine.direction;
    v.source = fine.source + " (2x level of detail)";
    v.background = fine.background;
    v.backgroundSource = fine.backgroundSource;
    return v;
}

namespace {

/// Sums of one coarse cell's splats.
struct CellSums {
    int count = 0;
    float density = 0;
    glm::vec4 emission{0.0f};
    glm::vec3 normal{0.0f}, weightedNormal{0.0f}, gradient{0.0f};
    float labels[8];
};

/// The label most splats of a cell carry (the lowest on a tie).
float commonLabel(const CellSums& c) {
    float best = c.labels[0];
    int bestCount = 0;
    for (int a = 0; a < c.count; ++a) {
        int n = 0;
        for (int b = 0; b < c.count; ++b) n += c.labels[b] == c.labels[a];
        if (n > bestCount || (n == bestCount && c.labels[a] < best)) {
            best = c.labels[a];
            bestCount = n;
        }
    }
    return best;
}

}  // namespace

SplatList coarserSplats(const SplatList& fine, const glm::ivec3& fd) {
    const glm::ivec3 cd = (fd + 1) / 2;
    const std::size_t ny = std::size_t(fd.y), n = fine.size();
    // Row (k, j) of the fine list: positions [row[k ny + j], row[k ny + j + 1]).
    std::vector<std::uint32_t> row(ny * std::size_t(fd.z) + 1, 0);
    for (std::size_t q = 0; q < n; ++q) ++row[std::size_t(fine.k[q]) * ny + fine.j[q] + 1];
    for (std::size_t r = 1; r < row.size(); ++r) row[r] += row[r - 1];
    // Calls f(q) for every fine splat of coarse row (K, J).
    auto forCell = [&](int K, int J, auto&& f) {
        for (int k = 2 * K; k < std::min(2 * K + 2, fd.z); ++k)
            for (int j = 2 * J; j < std::min(2 * J + 2, fd.y); ++j) {
                const std::size_t r = std::size_t(k) * ny + std::size_t(j);
                for (std::size_t q = row[r]; q < row[r + 1]; ++q) f(q);
            }
    };

    // Pass 1: splats per coarse slice K (cells holding at least one splat).
    std::vector<std::size_t> start(std::size_t(cd.z) + 1, 0);
    tbb::parallel_for(0, cd.z, [&](int K) {
        std::vector<std::uint8_t> occupied(std::size_t(cd.x), 0);
        std::size_t count = 0;
        for (int J = 0; J < cd.y; ++J) {
            forCell(K, J, [&](std::size_t q) {
                std::uint8_t& o = occupied[fine.i[q] / 2];
                count += o == 0;
                o = 1;
            });
            std::fill(occupied.begin(), occupied.end(), std::uint8_t(0));
        }
        start[std::size_t(K) + 1] = count;
    });
    for (std::size_t K = 1; K < start.size(); ++K) start[K] += start[K - 1];

    const bool hasEmission = fine.paletted() || !fine.extinction.empty();
    const bool normals = !fine.nx.empty(), gradients = !fine.gx.empty(),
               labels = !fine.label.empty();

    SplatList s;
    const std::size_t m = start.back();
    s.origin = fine.origin + 0.5 * fine.spacing;
    s.background = fine.background;  // merged densities are means of d - b
    s.spacing = 2.0 * fine.spacing;
    s.gradientScale = fine.gradientScale;
    s.voxels = std::size_t(cd.x) * std::size_t(cd.y) * std::size_t(cd.z);
    for (auto* a : {&s.i, &s.j, &s.k}) a->resize(m);
    s.density.resize(m);
    if (hasEmission)
        for (auto* a : {&s.extinction, &s.r, &s.g, &s.b}) a->resize(m);
    if (normals)
        for (auto* a : {&s.nx, &s.ny, &s.nz}) a->resize(m);
    if (gradients)
        for (auto* a : {&s.gx, &s.gy, &s.gz}) a->resize(m);
    if (labels) s.label.resize(m);

    // Pass 2: sum each coarse row's cells, write them in increasing I.
    constexpr float kEighth = 0.125f;
    tbb::parallel_for(0, cd.z, [&](int K) {
        std::vector<CellSums> cells(std::size_t(cd.x));
        std::size_t o = start[std::size_t(K)];
        for (int J = 0; J < cd.y; ++J) {
            forCell(K, J, [&](std::size_t q) {
                CellSums& c = cells[fine.i[q] / 2];
                c.density += fine.densityOf(q);
                const glm::vec4 e = hasEmission ? fine.emission(q) : glm::vec4(0.0f);
                c.emission += e;
                if (normals) {
                    const glm::vec3 nq(fine.nx[q], fine.ny[q], fine.nz[q]);
                    c.normal += nq;
                    c.weightedNormal += e.x * nq;
                }
                if (gradients) c.gradient += glm::vec3(fine.gx[q], fine.gy[q], fine.gz[q]);
                if (labels) c.labels[c.count] = fine.label[q];
                ++c.count;
            });
            for (int I = 0; I < cd.x; ++I) {
                CellSums& c = cells[std::size_t(I)];
                if (c.count == 0) continue;
                s.i[o] = std::uint16_t(I);
                s.j[o] = std::uint16_t(J);
                s.k[o] = std::uint16_t(K);
                s.density[o] = c.density * kEighth;
                if (!s.extinction.empty()) {
                    s.extinction[o] = c.emission.x * kEighth;
                    s.r[o] = c.emission.y * kEighth;
                    s.g[o] = c.emission.z * kEighth;
                    s.b[o] = c.emission.w * kEighth;
                }
                if (normals) {
                    // The normal that shades most of the cell's extinction (unweighted where
                    // the cell has none, e.g. label-only splats).
                    glm::vec3 nv =
                        glm::length(c.weightedNormal) > 0.0f ? c.weightedNormal : c.normal;
                    const float len = glm::length(nv);
                    nv = len > std::numeric_limits<float>::min() ? nv / len : glm::vec3(0.0f);
                    s.nx[o] = nv.x;
                    s.ny[o] = nv.y;
                    s.nz[o] = nv.z;
                }
                if (gradients) {
                    s.gx[o] = c.gradient.x * kEighth;
                    s.gy[o] = c.gradient.y * kEighth;
                    s.gz[o] = c.gradient.z * kEighth;
                }
                if (labels) s.label[o] = commonLabel(c);
                c = CellSums();
                ++o;
            }
        }
    });
    return s;
}

double voxelPixels(const Camera& camera, const Volume& volume) {
    const double voxel = std::max(volume.spacing.x, std::max(volume.spacing.y, volume.spacing.z));
    double pixel = camera.pixelSize;
    if (camera.perspective()) {
        // Nearest depth of the bounding sphere, where the voxel looks largest.
        const double nearest = camera.focal - camera.boundingRadius;
        if (!(nearest > 0.0)) return std::numeric_limits<double>::infinity();
        pixel *= nearest / camera.focal;
    }
    return voxel / pixel;
}

double lodBoxVariance(int level) { return (std::ldexp(1.0, 2 * level) - 1.0) / 12.0; }

LodFootprint lodFootprint(double k2, int level, double sigma, double voxelPixels0) {
    const double grid = std::ldexp(1.0, 2 * level);  // level voxel^2 in level-0 voxels^2
    const double narrowed = k2 - lodBoxVariance(level);
    if (narrowed >= kLodMinKernel * k2) return {std::sqrt(narrowed / (grid * k2)), sigma};
    const double rest = sigma * sigma - (lodBoxVariance(level) - (1.0 - kLodMinKernel) * k2) *
                                            voxelPixels0 * voxelPixels0;
    return {std::sqrt(kLodMinKernel / grid), std::sqrt(std::max(rest, 1e-6))};
}

bool lodAutoApplies(RenderMode mode) { return mode == RenderMode::Xray; }

int lodAutoLevel(double voxelPixels, double sigma, double kernelVariance, int maxLevel) {
    if (!(voxelPixels > 0) || !std::isfinite(voxelPixels)) return 0;
    const double v2 = voxelPixels * voxelPixels, s2 = sigma * sigma;
    int level = 0;
    while (level < maxLevel) {
        const int next = level + 1;
        const double footprint = (kernelVariance - lodBoxVariance(next)) * v2 + s2;
        if (!(footprint >= kLodAutoSmooth * std::ldexp(v2, 2 * next))) break;
        level = next;
    }
    return level;
}

}  // namespace splat
