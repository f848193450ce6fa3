// The pixel-filtered reference (see pixel_filter.h).
#include "reference/pixel_filter.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "splat/error.h"
#include "splat/metrics.h"

namespace splat {

namespace {

/// Weights of g_sigma, truncated at 4 sigma, at the fine offsets (j + 0.5) / s - 0.5 pixels
/// from a pixel centre, j = -half .. half + s - 1 (j counted from the pixel's first ray);
/// unnormalised (the 2D normalisation is the product of the 1D sums).
std::vector<double> taps(int s, double sigma, int& first) {
    const double cut = 4.0 * sigma;
    first = -int(std::ceil(cut * s));
    std::vector<double> w;
    for (int j = first; j <= s - 1 - first; ++j) {
        const double d = (j + 0.5) / s - 0.5;
        w.push_back(std::abs(d) <= cut ? std::exp(-0.5 * d * d / (sigma * sigma)) : 0.0);
    }
    double sum = 0;
    for (double x : w) sum += x;
    for (double& x : w) x /= sum;
    return w;
}

/// RMS difference over RGB (as compareImages) relative to the largest RGB value of `b`.
double relativeChange(const Image& a, const Image& b) {
    double peak = 0;
    for (const glm::vec4& p : b.pixels)
        peak = std::max(peak, double(std::max(p.r, std::max(p.g, p.b))));
    return compareImages(a, b).rmse / std::max(peak, 1e-30);
}

}  // namespace

CameraParams supersampledCamera(const Camera& camera, int s, int margin) {
    CameraParams p = camera.params();
    p.width = (camera.width() + 2 * margin) * s;
    p.height = (camera.height() + 2 * margin) * s;
    // Same eye and target: the fitted sizes (pixel size, perspective distance) made explicit.
    p.pixelSize = camera.pixelSize / s;
    if (camera.perspective() && !p.lookAtSet) p.distance = camera.focal;
    return p;
}

Image filterSupersampled(const Image& fine, int width, int height, int s, int margin,
                         double sigma) {
    int first = 0;
    const std::vector<double> w = taps(s, sigma, first);
    const int n = int(w.size());
    // Horizontal pass: fine (Wf x Hf) -> rows (width x Hf); then vertical.
    Image rows(width, fine.height);
    tbb::parallel_for(tbb::blocked_range<int>(0, fine.height), [&](const auto& r) {
        for (int y = r.begin(); y != r.end(); ++y)
            for (int x = 0; x < width; ++x) {
                const int k0 = (x + margin) * s + first;
                glm::dvec4 sum(0.0);
                for (int j = 0; j < n; ++j) sum += w[j] * glm::dvec4(fine.at(k0 + j, y));
                rows.at(x, y) = glm::vec4(sum);
            }
    });
    Image out(width, height);
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const auto& r) {
        for (int y = r.begin(); y != r.end(); ++y) {
            const int k0 = (y + margin) * s + first;
            for (int x = 0; x < width; ++x) {
                glm::dvec4 sum(0.0);
                for (int j = 0; j < n; ++j) sum += w[j] * glm::dvec4(rows.at(x, k0 + j));
                out.at(x, y) = glm::vec4(sum);
            }
        }
    });
    return out;
}

PixelFilterResult filteredImage(const Camera& camera, double sigma, double tolerance,
                                const std::function<Image(const CameraParams&)>& render) {
    if (!(sigma > 0 && sigma <= 4))
        throw Error("pixel filter sigma must be in (0, 4] pixels (0 = point sampling)");
    if (!(tolerance > 0) || !std::isfinite(tolerance))
        throw Error("pixel filter tolerance must be a positive number");
    const int margin = int(std::ceil(4.0 * sigma));
    PixelFilterResult result;
    for (int s = 2; s <= 16; s *= 2) {
        // Past 2^25 rays (512 MB of fine image) the last pass stands, its change reported.
        if (s > 2 && std::int64_t(camera.width() + 2 * margin) * (camera.height() + 2 * margin) *
                             s * s >
                         (std::int64_t(1) << 25))
            break;
        const Image fine = render(supersampledCamera(camera, s, margin));
        Image image = filterSupersampled(fine, camera.width(), camera.height(), s, margin, sigma);
        const bool converged = result.samples > 0 &&
                               (result.change = relativeChange(image, result.image)) <
                                   tolerance;
        result.image = std::move(image);
        result.samples = s;
        if (converged) break;
    }
    return result;
}

}  // namespace splat
