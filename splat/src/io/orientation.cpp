// The public face of the loaders' orientation step (splat/orientation.h).
#include "splat/orientation.h"

#include "volume_detail.h"

namespace splat {

void orientVolume(Volume& v, const glm::dmat3& M, const glm::dvec3& t, const std::string& what) {
    detail::applyOrientation(v, M, t, what);
}

bool isAxisAligned(const glm::dmat3& M) {
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            if (r == c ? !(M[c][r] > 0) : M[c][r] != 0) return false;
    return true;
}

}  // namespace splat
