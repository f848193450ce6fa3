// Orientation: turning a file's index-to-world affine into the model.
//
// Files store samples along their own index axes; the affine x = t + M p says where
// each index step goes in world space (RAS+: NIfTI sform/qform, NRRD space directions and
// DICOM/MetaImage LPS converted by their loaders). docs/design.md's volume has its index
// axes along the axes of its own frame with positive spacing, and a rotation `direction`
// from that frame to the world. We find the signed permutation closest to M (largest total
// |cosine| between each file axis and the world axis it is assigned to), reorder and flip
// the samples accordingly, and keep the rotation that is left in Volume::direction (the
// nearest rotation when the file's axes are not orthogonal, with a warning).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "splat/error.h"
#include "volume_detail.h"

namespace splat::detail {

namespace {

/// The rotation nearest to A (its polar factor, A (A^T A)^-1/2), by the Newton iteration
/// X <- (X + X^-T) / 2, quadratically convergent for a non-singular A.
glm::dmat3 nearestRotation(const glm::dmat3& A) {
    glm::dmat3 X = A;
    for (int it = 0; it < 50; ++it) {
        if (!(std::abs(glm::determinant(X)) > 1e-12)) return X;
        const glm::dmat3 next = 0.5 * (X + glm::transpose(glm::inverse(X)));
        double change = 0;
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) change = std::max(change, std::abs(next[c][r] - X[c][r]));
        X = next;
        if (change < 1e-15) break;
    }
    return X;
}

}  // namespace

AxisMap axisMapOf(const glm::dmat3& M, const std::string& source, const std::string& what) {
    AxisMap m;
    glm::dvec3 u[3];
    for (int a = 0; a < 3; ++a) {
        m.length[a] = glm::length(M[a]);
        if (!std::isfinite(m.length[a]) || m.length[a] <= 0)
            throw Error(source + ": " + what + " has a zero or invalid direction for axis " +
                        std::to_string(a));
        u[a] = M[a] / m.length[a];
    }
    // Best of the six permutations: perm[a] is the world axis of file axis a.
    std::array<int, 3> perm{0, 1, 2};
    double bestScore = -1;
    do {
        double score = 0;
        for (int a = 0; a < 3; ++a) score += std::abs(u[a][perm[a]]);
        if (score > bestScore + 1e-12) {
            bestScore = score;
            m.axis = perm;
        }
    } while (std::next_permutation(perm.begin(), perm.end()));
    for (int a = 0; a < 3; ++a) m.sign[a] = u[a][m.axis[a]] < 0 ? -1 : 1;
    return m;
}

void applyOrientation(Volume& v, const glm::dmat3& M, const glm::dvec3& t,
                      const std::string& what) {
    const AxisMap map = axisMapOf(M, v.source, what);
    const std::array<int, 3>& best = map.axis;
    const int* sign = map.sign;
    const double* len = map.length;

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
    if (!identity && !v.data.empty()) {  // no samples: the geometry alone
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

    // The rotation left: the columns of M in their new places, divided by their lengths.
    glm::dmat3 R;
    for (int a = 0; a < 3; ++a) R[best[a]] = M[a] * (double(sign[a]) / len[a]);
    const glm::dmat3 rotation = nearestRotation(R);
    double shear = 0, offAxis = 0;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) {
            shear = std::max(shear, std::abs(rotation[c][r] - R[c][r]));
            offAxis = std::max(offAxis, std::abs(rotation[c][r] - (c == r ? 1.0 : 0.0)));
        }
    if (!(glm::determinant(rotation) > 0.5))
        throw Error(v.source + ": " + what + " has axes that do not span space");
    if (shear > 1e-4) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "sheared orientation: the axes of the %s are not orthogonal (up to %.3g "
                      "off the nearest rotation), the nearest rotation was used",
                      what.c_str(), shear);
        addNote(v, buf);
    }
    // Below 1e-6 (a float32 affine's rounding), the volume is axis-aligned.
    if (offAxis > 1e-6) {
        v.direction = rotation;
        // world = t' + R S p = R (origin + S p): the volume-frame origin is R^T t'.
        v.origin = glm::transpose(rotation) * origin;
    }
}

}  // namespace splat::detail
