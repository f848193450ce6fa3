// View-dependent colour from real spherical harmonics, degree 0..3, in the basis and sign
// convention of 3D Gaussian Splatting (Kerbl et al. 2023; the constants are the real SH
// normalisations sqrt((2l + 1) / 4 pi) times the polynomial factors).
#include <algorithm>

#include "splat/gaussians.h"

namespace splat {

namespace {
constexpr float kC0 = 0.28209479177387814f;
constexpr float kC1 = 0.4886025119029199f;
constexpr float kC2[5] = {1.0925484305920792f, -1.0925484305920792f, 0.31539156525252005f,
                          -1.0925484305920792f, 0.5462742152960396f};
constexpr float kC3[7] = {-0.5900435899266435f, 2.890611442640554f,   -0.4570457994644658f,
                          0.3731763325901154f,  -0.4570457994644658f, 1.445305721320277f,
                          -0.5900435899266435f};
}  // namespace

glm::vec3 gaussianColour(const GaussianScene& scene, std::size_t i, const glm::vec3& dir) {
    const int count = scene.shCount();
    const float* c = scene.sh.data() + i * std::size_t(count) * 3;
    auto k = [c](int n) { return glm::vec3(c[3 * n], c[3 * n + 1], c[3 * n + 2]); };
    glm::vec3 r = kC0 * k(0);
    if (scene.shDegree > 0) {
        const float x = dir.x, y = dir.y, z = dir.z;
        r += -kC1 * y * k(1) + kC1 * z * k(2) - kC1 * x * k(3);
        if (scene.shDegree > 1) {
            const float xx = x * x, yy = y * y, zz = z * z;
            r += kC2[0] * x * y * k(4) + kC2[1] * y * z * k(5) +
                 kC2[2] * (2 * zz - xx - yy) * k(6) + kC2[3] * x * z * k(7) +
                 kC2[4] * (xx - yy) * k(8);
            if (scene.shDegree > 2)
                r += kC3[0] * y * (3 * xx - yy) * k(9) + kC3[1] * x * y * z * k(10) +
                     kC3[2] * y * (4 * zz - xx - yy) * k(11) +
                     kC3[3] * z * (2 * zz - 3 * xx - 3 * yy) * k(12) +
                     kC3[4] * x * (4 * zz - xx - yy) * k(13) + kC3[5] * z * (xx - yy) * k(14) +
                     kC3[6] * x * (xx - 3 * yy) * k(15);
        }
    }
    return glm::max(r + 0.5f, glm::vec3(0.0f));
}

}  // namespace splat
