// Error metrics between a test image and a reference, and difference heat maps.
//
// Foreground (meanAbsForeground): a pixel is foreground when its RGBA differs by more than
// 1e-6 in any channel from its image's background colour in either image. An image's
// background colour is the colour of its four corner pixels when they agree (to 1e-6),
// otherwise transparent black.
#include "splat/metrics.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "splat/error.h"
#include "splat/image_io.h"

namespace splat {
namespace {

constexpr float kSame = 1e-6f;

bool close(const glm::vec4& a, const glm::vec4& b) {
    const glm::vec4 d = glm::abs(a - b);
    return std::max(std::max(d.r, d.g), std::max(d.b, d.a)) <= kSame;
}

glm::vec4 backgroundOf(const Image& im) {
    const glm::vec4 c = im.at(0, 0);
    if (close(c, im.at(im.width - 1, 0)) && close(c, im.at(0, im.height - 1)) &&
        close(c, im.at(im.width - 1, im.height - 1)))
        return c;
    return glm::vec4(0.0f);
}

void checkSizes(const Image& test, const Image& reference) {
    if (test.width != reference.width || test.height != reference.height)
        throw Error("compare: image sizes differ (" + std::to_string(test.width) + "x" +
                    std::to_string(test.height) + " vs reference " +
                    std::to_string(reference.width) + "x" + std::to_string(reference.height) + ")");
    if (test.pixels.size() != std::size_t(test.width) * std::size_t(test.height) ||
        reference.pixels.size() != test.pixels.size())
        throw Error("compare: malformed image (pixel count does not match its size)");
}

}  // namespace

ImageMetrics compareImages(const Image& test, const Image& reference) {
    checkSizes(test, reference);
    ImageMetrics m;
    if (test.pixels.empty()) return m;
    const glm::vec4 bgTest = backgroundOf(test), bgRef = backgroundOf(reference);
    double sumSq = 0, sumFg = 0, peak = 0;
    for (std::size_t n = 0; n < test.pixels.size(); ++n) {
        const glm::vec4& a = test.pixels[n];
        const glm::vec4& b = reference.pixels[n];
        double pixelAbs = 0;
        for (int c = 0; c < 3; ++c) {
            const double d = double(a[c]) - double(b[c]);
            if (!std::isfinite(d)) {
                m.maxAbs = std::numeric_limits<double>::infinity();
                sumSq = std::numeric_limits<double>::infinity();
            } else {
                sumSq += d * d;
                m.maxAbs = std::max(m.maxAbs, std::abs(d));
            }
            pixelAbs += std::abs(d);
            peak = std::max(peak, double(b[c]));
        }
        if (!close(a, bgTest) || !close(b, bgRef)) {
            ++m.foregroundPixels;
            sumFg += pixelAbs / 3.0;
        }
    }
    m.rmse = std::sqrt(sumSq / (3.0 * double(test.pixels.size())));
    peak = std::max(peak, 1e-12);
    m.psnr =
        m.rmse > 0 ? 20.0 * std::log10(peak / m.rmse) : std::numeric_limits<double>::infinity();
    m.meanAbsForeground = m.foregroundPixels ? sumFg / double(m.foregroundPixels) : 0.0;
    return m;
}

void writeHeatmap(const std::string& path, const Image& test, const Image& reference,
                  double scale) {
    checkSizes(test, reference);
    if (test.pixels.empty()) throw Error("heat map: empty images, nothing to write to " + path);
    const int w = test.width, h = test.height;
    std::vector<float> diff(test.pixels.size());
    double maxDiff = 0;
    for (std::size_t n = 0; n < diff.size(); ++n) {
        const glm::vec4 d = glm::abs(test.pixels[n] - reference.pixels[n]);
        float v = std::max(d.r, std::max(d.g, d.b));
        if (!std::isfinite(v)) v = std::numeric_limits<float>::max();
        diff[n] = v;
        maxDiff = std::max(maxDiff, double(v));
    }
    if (!(scale > 0)) scale = maxDiff > 0 ? maxDiff : 1.0;
    for (float& v : diff) v = float(std::clamp(double(v) / scale, 0.0, 1.0));

    OIIO::ImageBuf grey(OIIO::ImageSpec(w, h, 1, OIIO::TypeDesc::FLOAT), diff.data());
    OIIO::ImageBuf mapped = OIIO::ImageBufAlgo::color_map(grey, 0, "inferno");
    if (mapped.has_error()) throw Error("heat map: colour map failed: " + mapped.geterror());

    // OpenImageIO's maps hold linear values: writeImage sRGB-encodes them for 8-bit files
    // and writes atomically (a temporary file in the same folder, renamed over the target).
    Image heat(w, h, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    std::vector<float> rgb(std::size_t(w) * h * 3);
    if (!mapped.get_pixels(OIIO::ROI(0, w, 0, h, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT, rgb.data()))
        throw Error(std::string("heat map: colour map failed: ").append(mapped.geterror()));
    for (std::size_t n = 0; n < heat.pixels.size(); ++n)
        heat.pixels[n] = glm::vec4(rgb[3 * n], rgb[3 * n + 1], rgb[3 * n + 2], 1.0f);
    writeImage(path, heat);
}

}  // namespace splat
