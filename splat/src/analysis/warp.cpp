// Frames warped with the exact flow of known cameras, and StopThePop's temporal FLIP
// (splat/warp.h).
#include "splat/warp.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "analysis/flip_image.h"
#include "splat/error.h"

namespace splat {

namespace {

constexpr double kCentreSnap = 1e-6;  // pixels

/// A continuous pixel coordinate's lower neighbour (pixel centres at n + 0.5) and weight of
/// the upper one; positions within kCentreSnap of a centre read that pixel alone.
void bilinear(double x, int& x0, double& f) {
    const double u = x - 0.5;
    const double r = std::round(u);
    if (std::abs(u - r) < kCentreSnap) {
        x0 = int(r);
        f = 0;
        return;
    }
    x0 = int(std::floor(u));
    f = u - x0;
}

/// Whether the later pixel's point P, at (px, py) in the earlier view, is what the earlier
/// view shows there (every pixel with bilinear weight has a depth within `tolerance` of P's
/// distance along that pixel's ray), and the bilinear sample of the earlier frame.
bool sampleVisible(const Image& earlier, const Image& depth, const Camera& camera,
                   const glm::dvec3& p, double px, double py, double tolerance, glm::vec4& out) {
    int x0, y0;
    double fx, fy;
    bilinear(px, x0, fx);
    bilinear(py, y0, fy);
    glm::dvec4 sum(0.0);
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const double w = (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
            if (w == 0) continue;
            const int x = x0 + i, y = y0 + j;
            if (x < 0 || y < 0 || x >= earlier.width || y >= earlier.height) return false;
            const glm::vec4& d = depth.at(x, y);
            if (d.a == 0) return false;
            const Ray ray = camera.ray(x + 0.5, y + 0.5);
            if (std::abs(glm::dot(p - ray.origin, ray.dir) - double(d.r)) > tolerance) return false;
            sum += w * glm::dvec4(earlier.at(x, y));
        }
    out = glm::vec4(sum);
    return true;
}

void checkSizes(const Image& a, const Image& b, const char* what) {
    if (a.width != b.width || a.height != b.height)
        throw Error(std::string("warp: ") + what + " differ in size");
}

}  // namespace

WarpedFrame warpFrame(const Image& earlier, const Image& earlierDepth, const Camera& earlierCamera,
                      const Image& later, const Image& laterDepth, const Camera& laterCamera,
                      const WarpOptions& options) {
    checkSizes(earlier, earlierDepth, "the earlier frame and its depth");
    checkSizes(later, laterDepth, "the later frame and its depth");
    checkSizes(earlier, later, "the two frames");
    if (options.border < 0 || !(options.depthTolerance > 0))
        throw Error("warp: the border must be >= 0 and the depth tolerance > 0");
    const int w = later.width, h = later.height, b = options.border;
    const double tolerance = options.depthTolerance * 2 * earlierCamera.boundingRadius;
    WarpedFrame out;
    out.image = later;
    out.valid.assign(later.pixels.size(), 0);
    tbb::parallel_for(0, h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            const glm::vec4& d = laterDepth.at(x, y);
            if (d.a == 0 || x < b || y < b || x >= w - b || y >= h - b) continue;
            const Ray ray = laterCamera.ray(x + 0.5, y + 0.5);
            const glm::dvec3 p = ray.origin + double(d.r) * ray.dir;
            const glm::dvec3 q = earlierCamera.project(p);
            if (!(q.x >= b && q.y >= b && q.x <= w - b && q.y <= h - b)) continue;
            glm::vec4 sample;
            if (!sampleVisible(earlier, earlierDepth, earlierCamera, p, q.x, q.y, tolerance,
                               sample))
                continue;
            out.image.at(x, y) = sample;
            out.valid[std::size_t(y) * w + x] = 1;
        }
    });
    out.validCount = std::size_t(std::count(out.valid.begin(), out.valid.end(), 1));
    return out;
}

double warpedFlip(const Image& later, const WarpedFrame& warped, const FlipOptions& options) {
    if (warped.validCount == 0) return -1;
    return analysis::warpedFlip(analysis::FlipImage(later, options), warped);
}

namespace analysis {

double warpedFlip(const FlipImage& later, const WarpedFrame& warped) {
    if (warped.validCount == 0) return -1;
    FlipOptions options;
    options.pixelsPerDegree = later.pixelsPerDegree();
    const std::vector<float> map = flipErrorMap(later, FlipImage(warped.image, options));
    double sum = 0;
    for (std::size_t p = 0; p < map.size(); ++p)
        if (warped.valid[p]) sum += map[p];
    return sum / double(warped.validCount);
}

}  // namespace analysis

}  // namespace splat
