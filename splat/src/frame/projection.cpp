// Pipeline stage "project" (see projection.h).
#include "projection.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "model/level_of_detail.h"

namespace splat {

namespace {

/// Auto: X-ray, where the image is linear in the footprints and EWA is the filtered
/// reference's convolution (docs/accuracy.md "Aliasing and EWA": 21-42x lower error). Not dvr: the
/// low-pass widens extinction before the exponential, so opaque silhouettes grow (measured
/// worse on phantom:64 ct-soft); nor mip, iso (a maximum and a first hit of a blurred field).
bool ewaAutoApplies(RenderMode mode) { return mode == RenderMode::Xray; }

}  // namespace

double ewaLowPass(const Quality& quality, RenderMode mode, const Camera& camera,
                  const Volume& volume) {
    const bool on = quality.ewa == Ewa::On ||
                    (quality.ewa == Ewa::Auto && ewaAutoApplies(mode) &&
                     voxelPixels(camera, volume) < Quality::kEwaAutoPixels);
    if (!on) return 0;
    return quality.pixelFilter > 0 ? quality.pixelFilter : Quality::kEwaDefaultSigma;
}

FootprintFilter footprintFilter(const footprint::Kernel& kernel, const Quality& quality,
                                RenderMode mode, const Camera& camera, const Volume& volume,
                                int level) {
    if (quality.lod.filtered() && level > 0) {
        const LodFootprint f = lodFootprint(
            kernel.variance(), level,
            quality.pixelFilter > 0 ? quality.pixelFilter : Quality::kEwaDefaultSigma,
            std::ldexp(voxelPixels(camera, volume), -level));
        return {kernel.variance(), f.lowPass, f.kernelScale};
    }
    const double lowPass = ewaLowPass(quality, mode, camera, volume);
    if (!(lowPass > 0)) return {};
    return {kernel.variance(), lowPass};
}

void projectSplats(const SplatList& splats, const Camera& camera, const glm::dvec3& gridSpacing,
                   double radius, ProjectedSplats& p, const FootprintFilter& filter) {
    const std::size_t n = splats.size();
    p.sx.resize(n);
    p.sy.resize(n);
    p.depth.resize(n);
    p.rect.resize(n);
    p.perspective = camera.perspective();
    // The kernel is the ellipsoid S * (ball of radius R); its extent along a unit
    // direction n is R |S n| (the support function of the ellipsoid).
    const glm::dvec3 spacing = filter.kernelSpacing(gridSpacing);
    p.depthExtent = float(radius * glm::length(spacing * camera.view));
    if (!p.perspective) {
        p.shared = filter.apply(
            footprint::ellipticalFootprint(spacing, camera.right * camera.pixelSize,
                                           -camera.up * camera.pixelSize, camera.view, radius),
            radius);
        p.each.clear();
        p.depthPerRay.clear();
    } else {
        p.each.resize(n);
        p.depthPerRay.resize(n);
    }
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t s = r.begin(); s != r.end(); ++s) {
                const glm::dvec3 w = splats.world(s);
                const glm::dvec3 q = camera.project(w);
                p.sx[s] = float(q.x);
                p.sy[s] = float(q.y);
                p.depth[s] = float(q.z);
                if (p.perspective) {
                    p.each[s] = filter.apply(
                        footprint::perspectiveFootprint(spacing, camera.eye, camera.right,
                                                        camera.up, camera.view, camera.focal,
                                                        camera.pixelSize, w, radius),
                        radius);
                    p.depthPerRay[s] =
                        float(1.0 / glm::dot(glm::normalize(w - camera.eye), camera.view));
                }
                p.rect[s] = p.perspective && !(q.z > 0.0)
                                ? PixelRect{1, 1, 0, 0}
                                : footprintRect(p.sx[s], p.sy[s], p.ellipse(s), camera.width(),
                                                camera.height());
            }
        });
}

SplatProjector::SplatProjector(const SplatList& splats, const Camera& camera,
                               const glm::dvec3& spacing, double radius,
                               const FootprintFilter& filter)
    : splats_(splats),
      camera_(camera),
      spacing_(filter.kernelSpacing(spacing)),
      radius_(radius),
      filter_(filter),
      perspective_(camera.perspective()),
      width_(camera.width()),
      height_(camera.height()),
      cx_(0.5 * camera.width()),
      cy_(0.5 * camera.height()),
      rx_(camera.right / camera.pixelSize),
      ry_(camera.up / camera.pixelSize) {
    if (!perspective_)
        shared_ = filter_.apply(
            footprint::ellipticalFootprint(spacing_, camera.right * camera.pixelSize,
                                           -camera.up * camera.pixelSize, camera.view, radius),
            radius);
}

PixelRect SplatProjector::projectPerspective(const glm::dvec3& w, float& sx, float& sy,
                                             footprint::EllipticalFootprint& e) const {
    const glm::dvec3 q = camera_.project(w);
    sx = float(q.x);
    sy = float(q.y);
    e = filter_.apply(footprint::perspectiveFootprint(spacing_, camera_.eye, camera_.right,
                                                      camera_.up, camera_.view, camera_.focal,
                                                      camera_.pixelSize, w, radius_),
                      radius_);
    if (!(q.z > 0.0)) return {1, 1, 0, 0};
    return footprintRect(sx, sy, e, width_, height_);
}

std::vector<float> perspectivePathScale(const Camera& camera, const glm::dvec3& axis) {
    if (!camera.perspective()) return {};
    const int w = camera.width(), h = camera.height();
    std::vector<float> scale(std::size_t(w) * h);
    const double ref = std::abs(glm::dot(camera.view, axis));
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x = 0; x < w; ++x) {
                const Ray r = camera.ray(x + 0.5, y + 0.5);
                scale[std::size_t(y) * w + x] = float(ref / std::abs(glm::dot(r.dir, axis)));
            }
    });
    return scale;
}

}  // namespace splat
