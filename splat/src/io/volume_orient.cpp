// Orientation: turning a file's index-to-world affine into the axis-aligned model.
//
// Files store samples along their own index axes; the affine x = t + M p says where
// each index step goes in world space (NIfTI sform/qform in RAS+, NRRD space
// directions). splat/DESIGN.md's volume has world axes along index axes with positive
// spacing, so we find the signed permutation closest to M (largest total |cosine|
// between each file axis and the world axis it is assigned to), reorder and flip the
// samples accordingly, and report whatever rotation is left.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "splat/error.h"
#include "volume_detail.h"

namespace splat::detail {

void applyOrientation(Volume& v, const glm::dmat3& M, const glm::dvec3& t,
                      const std::string& what) {
    glm::dvec3 u[3];
    double len[3];
    for (int a = 0; a < 3; ++a) {
        len[a] = glm::length(M[a]);
        if (!std::isfinite(len[a]) || len[a] <= 0)
            throw Error(v.source + ": " + what + " has a zero or invalid direction for axis " +
                        std::to_string(a));
        u[a] = M[a] / len[a];
    }
    // Best of the six permutations: perm[a] is the world axis of file axis a.
    std::array<int, 3> perm{0, 1, 2}, best = perm;
    double bestScore = -1;
    do {
        double score = 0;
        for (int a = 0; a < 3; ++a) score += std::abs(u[a][perm[a]]);
        if (score > bestScore + 1e-12) {
            bestScore = score;
            best = perm;
        }
    } while (std::next_permutation(perm.begin(), perm.end()));

    int sign[3];
    double worst = 0;  // largest angle between a file axis and its assigned world axis
    for (int a = 0; a < 3; ++a) {
        double c = u[a][best[a]];
        sign[a] = c < 0 ? -1 : 1;
        worst = std::max(worst, std::acos(std::min(1.0, std::abs(c))));
    }

    const glm::ivec3 fileDims = v.dims;
    glm::ivec3 dims;
    glm::dvec3 spacing;
    glm::dvec3 origin = t;
    for (int a = 0; a < 3; ++a) {
        dims[best[a]] = fileDims[a];
        spacing[best[a]] = len[a];
        if (sign[a] < 0) origin += M[a] * double(fileDims[a] - 1);
    }

    bool identity =
        best == std::array<int, 3>{0, 1, 2} && sign[0] > 0 && sign[1] > 0 && sign[2] > 0;
    if (!identity) {
        std::vector<float> out(v.data.size());
        const std::size_t nx = std::size_t(dims.x), ny = std::size_t(dims.y);
        // Destination index step (in samples) and start for one step along each file axis.
        std::ptrdiff_t step[3];
        std::ptrdiff_t start = 0;
        for (int a = 0; a < 3; ++a) {
            std::ptrdiff_t s = best[a] == 0   ? 1
                               : best[a] == 1 ? std::ptrdiff_t(nx)
                                              : std::ptrdiff_t(nx * ny);
            if (sign[a] < 0) {
                start += s * (fileDims[a] - 1);
                s = -s;
            }
            step[a] = s;
        }
        std::size_t src = 0;
        for (int k = 0; k < fileDims.z; ++k)
            for (int j = 0; j < fileDims.y; ++j) {
                std::ptrdiff_t dst = start + step[2] * k + step[1] * j;
                for (int i = 0; i < fileDims.x; ++i, ++src, dst += step[0])
                    out[std::size_t(dst)] = v.data[src];
            }
        v.data.swap(out);
    }
    v.dims = dims;
    v.spacing = spacing;
    v.origin = origin;

    if (worst > 1e-3) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "oblique orientation: the %s is rotated up to %.2f degrees from the "
                      "nearest axis-aligned orientation; only axis flips/permutations were "
                      "applied, the rest of the rotation is not",
                      what.c_str(), worst * 180.0 / M_PI);
        if (!v.note.empty()) v.note += "; ";
        v.note += buf;
    }
}

}  // namespace splat::detail
