// `reference`: the volume rendering integral of splat/gaussians.h's density field along each
// pixel ray, I = int e(t) exp(-int_0^t sigma) dt. The optical depth and emission accumulated up
// to t are closed forms (projection.h RayGaussian):
//     tau(t) = sum_i A_i (1 + erf(s_i (t - t*_i))),   E(t) = sum_i k_i A_i (1 + erf(...)),
// so every segment [t0, t1] has its exact optical depth and emission, and is composited as a
// sheet (alpha = 1 - exp(-dtau), C = dE alpha / dtau). That is exact when one colour fills
// the segment; where colours mix, segments are halved until the one-piece and the two-halves
// results differ by at most `tolerance` times the segment's share of the ray, weighted by the
// transmittance in front of it (at least 16 segments; at most 2^30 per ray).
#include <algorithm>
#include <cmath>
#include <vector>

#include "renderers.h"

namespace splat::gaussians {

namespace {

constexpr double kErfReach = 4.5;
constexpr int kMinDepth = 4, kMaxDepth = 30;

struct Accumulated {
    double tau;
    glm::dvec3 emission;
};

class RayIntegral {
  public:
    RayIntegral(const std::vector<RayGaussian>& gs, double tolerance) : gs_(gs) {
        t0_ = INFINITY;
        t1_ = -INFINITY;
        for (const RayGaussian& g : gs) {
            t0_ = std::min(t0_, g.tStar - kErfReach / g.s);
            t1_ = std::max(t1_, g.tStar + kErfReach / g.s);
        }
        t0_ = std::max(t0_, 0.0);  // the ray starts at the eye (or in front of the scene)
        perLength_ = tolerance / (t1_ - t0_);
    }
    glm::vec4 run() {
        if (!(t1_ > t0_)) return out_.pixel();
        segment(t0_, t1_, at(t0_), at(t1_), 0);
        return out_.pixel();
    }

  private:
    Accumulated at(double t) const {
        Accumulated a{0.0, glm::dvec3(0.0)};
        for (const RayGaussian& g : gs_) {
            const double w = g.amplitude * (1 + std::erf(g.s * (t - g.tStar)));
            a.tau += w;
            a.emission += glm::dvec3(g.colour) * w;
        }
        return a;
    }
    void segment(double t0, double t1, const Accumulated& a0, const Accumulated& a1, int depth) {
        const double tm = 0.5 * (t0 + t1);
        const Accumulated am = at(tm);
        FrontToBack one, two;
        one.sheet(a1.tau - a0.tau, a1.emission - a0.emission);
        two.sheet(am.tau - a0.tau, am.emission - a0.emission);
        two.sheet(a1.tau - am.tau, a1.emission - am.emission);
        const glm::dvec3 diff = glm::abs(one.colour - two.colour);
        const double error = out_.transmittance * std::max({diff.x, diff.y, diff.z});
        if (depth >= kMaxDepth || (depth >= kMinDepth && error <= perLength_ * (t1 - t0))) {
            out_.sheet(am.tau - a0.tau, am.emission - a0.emission);
            out_.sheet(a1.tau - am.tau, a1.emission - am.emission);
            return;
        }
        segment(t0, tm, a0, am, depth + 1);
        segment(tm, t1, am, a1, depth + 1);
    }

    const std::vector<RayGaussian>& gs_;
    double t0_, t1_, perLength_;
    FrontToBack out_;
};

}  // namespace

Image renderReference(const GaussianScene& scene, const Projected& p, const TileLists& tiles,
                      const Camera& camera, double tolerance, double epsilon) {
    Image image(camera.width(), camera.height());
    forEachPixelRay(scene, p, tiles, camera, epsilon,
                    [&](int x, int y, const std::vector<RayGaussian>& gs) {
                        image.at(x, y) = RayIntegral(gs, tolerance).run();
                    });
    return image;
}

}  // namespace splat::gaussians
