#pragma once
// Test helpers around the reference ray caster: render the exact model for a volume and
// settings, build splat lists by hand, and the closed forms of one kernel.
#include <cmath>
#include <glm/glm.hpp>

#include "footprint/footprint_table.h"
#include "footprint/kernel.h"
#include "splat/camera.h"
#include "splat/classify.h"
#include "splat/image.h"
#include "splat/metrics.h"
#include "splat/reference.h"
#include "splat/render.h"
#include "splat/volume.h"

namespace splat::test {

/// The kernel that `settings` asks for.
inline footprint::Kernel kernelOf(const RenderSettings& s) {
    return footprint::Kernel::fromName(s.kernel, s.kernelSigma, s.kernelRadius);
}

/// Resolves a normalized transfer function onto the volume's value range.
inline TransferFunction resolvedFor(const TransferFunction& tf, const Volume& v) {
    float lo = v.data.empty() ? 0.0f : v.data[0], hi = lo;
    for (float d : v.data) {
        lo = std::min(lo, d);
        hi = std::max(hi, d);
    }
    return tf.resolved(lo, hi);
}

/// Reference image of `volume` under `settings` (a normalized transfer function is resolved
/// onto the volume's range first), classified exactly as the renderers classify it.
/// `depth`: iso hit depths (iso only).
inline Image referenceImage(const Volume& volume, RenderSettings settings,
                            RenderStats* stats = nullptr, Image* depth = nullptr) {
    if (settings.transfer.normalized) settings.transfer = resolvedFor(settings.transfer, volume);
    const footprint::Kernel kernel = kernelOf(settings);
    const SplatList splats = classify(volume, settings.transfer, settings.mode,
                                      settings.classification, kernel.radius());
    const Camera camera(settings.camera, volume);
    if (depth) *depth = renderReferenceDepth(volume, splats, kernel, camera, settings);
    return renderReference(volume, splats, kernel, camera, settings, stats);
}

/// A splat for every non-zero voxel, by hand: density d, extinction rhoPerUnit * d and
/// emission colour * extinction (pre-classified with a constant colour).
inline SplatList splatsByHand(const Volume& v, float rhoPerUnit = 1.0f,
                              const glm::vec3& colour = glm::vec3(1.0f)) {
    SplatList s;
    s.origin = v.origin;
    s.spacing = v.spacing;
    for (int k = 0; k < v.dims.z; ++k)
        for (int j = 0; j < v.dims.y; ++j)
            for (int i = 0; i < v.dims.x; ++i) {
                const float d = v.at(i, j, k);
                ++s.voxels;
                if (d == 0.0f) continue;
                s.i.push_back(std::uint16_t(i));
                s.j.push_back(std::uint16_t(j));
                s.k.push_back(std::uint16_t(k));
                s.density.push_back(d);
                const float rho = rhoPerUnit * d;
                s.extinction.push_back(rho);
                s.r.push_back(colour.r * rho);
                s.g.push_back(colour.g * rho);
                s.b.push_back(colour.b * rho);
            }
    return s;
}

/// Perpendicular distance (index units) of `ray` from voxel `p`, and |S^-1 dir|: the line
/// integral of that voxel's kernel along the ray is fp(r) / |v| (docs/design.md "Footprints").
struct KernelLine {
    double r = 0, vLen = 1;
};
inline KernelLine kernelLine(const Volume& v, const Ray& ray, const glm::dvec3& p) {
    const glm::dvec3 p0 = (ray.origin - v.world(p)) / v.spacing;
    const glm::dvec3 dir = ray.dir / v.spacing;
    const double vl = glm::length(dir);
    const double along = glm::dot(p0, dir) / vl;
    return {std::sqrt(std::max(0.0, glm::dot(p0, p0) - along * along)), vl};
}

/// Exact optical depth of a pre-classified splat list along `ray`: sum rho_i fp(r_i) / |v|.
inline double exactOpticalDepth(const Volume& v, const SplatList& s,
                                const footprint::FootprintTable& fp, const Ray& ray) {
    double tau = 0;
    for (std::size_t n = 0; n < s.size(); ++n) {
        const KernelLine l = kernelLine(v, ray, glm::dvec3(s.i[n], s.j[n], s.k[n]));
        if (l.r >= fp.radius()) continue;
        tau += s.extinction[n] * fp.exact(l.r) / l.vLen;
    }
    return tau;
}

}  // namespace splat::test
