// A volume's splats as a 3DGS scene (splat/gaussians.h gaussiansFromVolume): one Gaussian per
// pre-classified splat, the kernel's sigma (voxels) times the spacing as its scales, the
// transfer function's colour e_i / rho_i, and the opacity of the splat's Westover footprint
// at its centre, o_i = 1 - exp(-rho_i s / (2 pi sigma^2)) for isotropic spacing s (the line
// integral of the normalised Gaussian kernel through its centre is 1 / (2 pi sigma^2) voxels).
// Then the density of the volumetric model (c_i G_i) is the kernel's rho_i h: the Gaussian
// reference renders the volume's model, up to the kernel's truncation at R and opacities
// clamped at 0.99 (rho_i s / (2 pi sigma^2) <= 4.6).
#include <cmath>

#include "footprint/kernel.h"
#include "splat/classify.h"
#include "splat/error.h"
#include "splat/gaussians.h"
#include "splat/settings.h"

namespace splat {

GaussianScene gaussiansFromVolume(const Volume& volume, const RenderSettings& settings) {
    footprint::Kernel kernel = footprint::Kernel::defaultKernel();
    try {
        kernel = footprint::Kernel::fromName(settings.kernel, settings.kernelSigma,
                                             settings.kernelRadius);
    } catch (const std::invalid_argument& e) {
        throw Error(e.what());
    }
    if (settings.kernel != "gaussian")
        throw Error("a volume becomes Gaussians only with the gaussian kernel (--kernel gaussian)");
    const bool isotropic =
        volume.spacing.x == volume.spacing.y && volume.spacing.y == volume.spacing.z;
    if (volume.direction != glm::dmat3(1.0) && !isotropic)
        throw Error(
            "an oblique volume with anisotropic spacing cannot be written as Gaussians yet");
    const VolumeStats st = volumeStats(volume, 1);
    const TransferFunction tf = settings.transfer.resolved(st.minValue, st.maxValue);
    SplatList splats = classify(volume, tf, RenderMode::Dvr, Classification::Pre, kernel.radius());
    splats.expandEmission();
    constexpr double kPi = 3.14159265358979323846;
    const double sigma = kernel.sigma(), voxel = volume.minSpacing();
    const double perRho = voxel / (2 * kPi * sigma * sigma);
    GaussianScene s;
    s.shDegree = 0;
    const std::size_t n = splats.size();
    if (n > kMaxGaussians) throw Error("the volume has more splats than a Gaussian scene holds");
    s.means.resize(n);
    s.scales.assign(n, glm::vec3(sigma * volume.spacing));
    s.rotations.assign(n, glm::vec4(1, 0, 0, 0));
    s.opacities.resize(n);
    s.sh.resize(n * 3);
    for (std::size_t i = 0; i < n; ++i) {
        s.means[i] = glm::vec3(volume.direction * splats.world(i));
        const double rho = splats.extinction[i];
        s.opacities[i] = float(-std::expm1(-rho * perRho));
        const glm::dvec3 e(splats.r[i], splats.g[i], splats.b[i]);
        const glm::dvec3 colour = rho > 0 ? e / rho : glm::dvec3(0.0);
        for (int c = 0; c < 3; ++c)
            s.sh[i * 3 + std::size_t(c)] = float((colour[c] - 0.5) / 0.28209479177387814);
    }
    s.source = "Gaussians of " + (volume.source.empty() ? std::string("a volume") : volume.source);
    return s;
}

}  // namespace splat
