// The median-opacity depth of a volume Scene's reference (splat/depth.h): each pixel ray is
// clipped to the volume's box widened by the kernel radius and marched at half the smallest
// spacing (stopping once the optical depth exceeds 20) through the reference's extinction field
// rho(x) (pre-classified: the kernel sum of the splats' rho_i; post-classified: the transfer
// function's extinction of f(x)); the optical depth is integrated by the trapezoid rule and t_1/2
// interpolated linearly within the step where it is crossed. Pre-classified, the samples outside
// the field's occupied bricks are 0 without being evaluated (the same sums, fewer lookups).
#include "splat/depth.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "model/scene_impl.h"
#include "reference/field.h"
#include "reference/reference_frame.h"

namespace splat {

namespace {

constexpr double kStepVoxels = 0.5;
constexpr double kOpaque = 20;  // optical depth beyond which a ray's opacity is 1 to 2e-9

/// The field the depth reads, per Scene (Scene::Impl::state), made on first use: the
/// extinction itself (pre-classified, a one-channel field of the splats' rho_i) or f.
class DepthField {
  public:
    explicit DepthField(const Scene::Impl& scene) : scene_(scene) {}
    const ReferenceField& field() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!field_) {
            if (scene_.settings.classification == Classification::Pre) {
                SplatList rho = scene_.splats;
                if (rho.paletted()) rho.expandEmission();
                rho.density = rho.extinction;
                rho.background = 0;
                field_ = std::make_unique<ReferenceField>(*scene_.volume, rho, scene_.kernel,
                                                          FieldLayout::Density);
            } else {
                field_ = std::make_unique<ReferenceField>(*scene_.volume, scene_.splats,
                                                          scene_.kernel, FieldLayout::Density);
            }
        }
        return *field_;
    }

  private:
    const Scene::Impl& scene_;
    std::mutex mutex_;
    std::unique_ptr<const ReferenceField> field_;
};

/// [t0, t1] of the ray inside the box (t0 >= 0), or t0 > t1 where it misses.
void clipToBox(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi, double& t0, double& t1) {
    t0 = 0;
    t1 = INFINITY;
    for (int a = 0; a < 3; ++a) {
        if (ray.dir[a] == 0) {
            if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a]) t0 = INFINITY;
            continue;
        }
        double u = (lo[a] - ray.origin[a]) / ray.dir[a], v = (hi[a] - ray.origin[a]) / ray.dir[a];
        if (u > v) std::swap(u, v);
        t0 = std::max(t0, u);
        t1 = std::min(t1, v);
    }
}

/// t_1/2 along one ray from its extinction samples rho(t0 + n dt), or -1 without a depth.
double medianOpacityDepth(const std::vector<double>& rho, double t0, double dt) {
    std::vector<double> tau(rho.size(), 0.0);
    for (std::size_t n = 1; n < rho.size(); ++n)
        tau[n] = tau[n - 1] + 0.5 * (rho[n - 1] + rho[n]) * dt;
    const double total = rho.empty() ? 0.0 : -std::expm1(-tau.back());
    if (!(total >= kDepthMinOpacity)) return -1;
    const double tauHalf = -std::log1p(-0.5 * total);
    const std::size_t n =
        std::size_t(std::lower_bound(tau.begin(), tau.end(), tauHalf) - tau.begin());
    if (n == 0) return t0;
    const double f = (tauHalf - tau[n - 1]) / (tau[n] - tau[n - 1]);
    return t0 + (double(n - 1) + f) * dt;
}

/// Pre-classified: which samples of a ray may see extinction. The field is exactly 0 outside
/// the bricks the field grid marks occupied (reference/field.h), so a sample there is 0
/// without its sum. Samples within a thousandth of a step of an occupied segment are evaluated
/// too, so that the segments' and the samples' rounding cannot skip a non-zero sample.
class OccupiedSpans {
  public:
    OccupiedSpans(const FieldGrid<1>& grid, const Volume& volume, const Ray& ray, double t0,
                  double t1, double dt)
        : margin_(1e-3 * dt) {
        const glm::dvec3 p0 = (ray.origin - volume.origin) / volume.spacing;
        raySegments(grid, p0, ray.dir / volume.spacing, t0, t1, segments_);
    }
    /// Whether the sample at t (called with t increasing) lies in or near an occupied segment.
    bool occupied(double t) {
        while (next_ < segments_.size() && t > segments_[next_].b + margin_) ++next_;
        return next_ < segments_.size() && t >= segments_[next_].a - margin_;
    }

  private:
    double margin_;
    std::vector<Segment> segments_;
    std::size_t next_ = 0;
};

}  // namespace

Image dvrMedianDepth(const Scene& scene, const Camera& camera, bool skipEmpty) {
    const Scene::Impl& impl = scene.impl();
    const Volume& volume = *impl.volume;
    const ReferenceField& field = impl.state<DepthField>().field();
    const bool pre = impl.settings.classification == Classification::Pre;
    const TransferFunction& transfer = impl.settings.transfer;
    auto extinction = [&](const glm::dvec3& x) {
        const double v = field.density(volume, x);
        return pre ? std::max(0.0, v) : double(transfer.extinction(float(v)));
    };
    const glm::dvec3 reach = impl.kernel.radius() * volume.spacing;
    const glm::dvec3 lo = volume.origin - reach;
    const glm::dvec3 hi = volume.world(glm::dvec3(volume.dims) - 1.0) + reach;
    const double dt =
        kStepVoxels * std::min({volume.spacing.x, volume.spacing.y, volume.spacing.z});
    Image depth(camera.width(), camera.height());
    tbb::parallel_for(0, camera.height(), [&](int y) {
        std::vector<double> rho;
        for (int x = 0; x < camera.width(); ++x) {
            const Ray ray = camera.ray(x + 0.5, y + 0.5);
            double t0, t1;
            clipToBox(ray, lo, hi, t0, t1);
            if (!(t1 > t0)) continue;
            const int steps = int(std::ceil((t1 - t0) / dt));
            rho.resize(std::size_t(steps) + 1);
            // Post-classified, empty space has the transfer function's extinction at b.
            std::optional<OccupiedSpans> spans;
            if (pre && skipEmpty)
                spans.emplace(field.grid1(), volume, ray, t0, t0 + steps * dt, dt);
            double tau = 0;
            for (int n = 0; n <= steps; ++n) {
                const double t = t0 + n * dt;
                rho[n] = spans && !spans->occupied(t) ? 0.0 : extinction(ray.origin + t * ray.dir);
                tau += rho[n] * dt;
                if (tau > kOpaque) {
                    rho.resize(std::size_t(n) + 1);
                    break;
                }
            }
            const double t = medianOpacityDepth(rho, t0, dt);
            if (t >= 0) depth.at(x, y) = glm::vec4(float(t), float(t), float(t), 1.0f);
        }
    });
    return depth;
}

Image referenceDepth(const Scene& scene, const CameraParams& params) {
    const RenderSettings& s = scene.settings();
    if (s.mode == RenderMode::Iso) {
        RenderSettings frame = s;
        frame.renderer = RendererKind::Reference;
        frame.camera = params;
        return scene.renderIsoDepth(frame);
    }
    const Camera camera(params, scene.volume());
    if (s.mode != RenderMode::Dvr) return Image(camera.width(), camera.height());
    Image depth;
    runOnThreads(s.threads, [&] { depth = dvrMedianDepth(scene, camera); });
    return depth;
}

}  // namespace splat
