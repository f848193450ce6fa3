// Images in and out (splat/image_io.h) and their comparison (splat/metrics.h, splat/flip.h):
// arrays H x W x 4 float32, premultiplied RGBA, row 0 on top.
#include <cmath>

#include "py_common.h"
#include "splat/flip.h"
#include "splat/image_io.h"
#include "splat/metrics.h"
#include "splat/version.h"

namespace splat::python {

Image fromArray(const py::array& input, const char* what) {
    auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(input);
    if (!a || a.ndim() != 3 || (a.shape(2) != 4 && a.shape(2) != 3) || a.shape(0) < 1 ||
        a.shape(1) < 1 || a.shape(0) > 65536 || a.shape(1) > 65536)
        throw Error(std::string(what) +
                    ": an image must be an H x W x 4 (RGBA) or H x W x 3 (RGB) array of numbers");
    Image im(int(a.shape(1)), int(a.shape(0)), glm::vec4(1.0f));
    const float* p = a.data();
    const int c = int(a.shape(2));
    for (std::size_t n = 0; n < im.pixels.size(); ++n)
        for (int k = 0; k < c; ++k) im.pixels[n][k] = p[n * c + k];
    return im;
}

namespace {

py::dict metricsDict(const ImageMetrics& m) {
    py::dict d;
    d["rmse"] = m.rmse;
    d["psnr"] = m.psnr;
    d["max_abs"] = m.maxAbs;
    d["mean_abs_foreground"] = m.meanAbsForeground;
    d["foreground_pixels"] = m.foregroundPixels;
    return d;
}

FlipOptions flipOptions(double ppd) {
    FlipOptions o;
    o.pixelsPerDegree = ppd;
    return o;
}

}  // namespace

void bindImage(py::module_& m) {
    m.def(
        "read_image",
        [](const std::string& path) {
            Image im;
            {
                py::gil_scoped_release release;
                try {
                    im = readImage(path);
                } catch (const Error& e) {
                    rethrowFileError(e, path, true);
                }
            }
            return toArray(std::move(im));
        },
        py::arg("path"),
        "Reads any image OpenImageIO reads (.exr, .tif, .png, ...) as H x W x 4 float32 RGBA "
        "(missing alpha: 1), values as stored.");
    m.def(
        "write_image",
        [](const std::string& path, const py::array& image, const py::object& window, int bitDepth,
           bool alpha) {
            const Image im = fromArray(image, "write_image");
            WriteOptions o;
            if (!window.is_none()) {
                const auto w = window.cast<std::pair<double, double>>();
                if (!std::isfinite(w.first) || !std::isfinite(w.second) || !(w.second > w.first))
                    throw Error("--window needs finite LOW,HIGH with HIGH > LOW");
                o.mapping = DisplayMapping::Window;
                o.windowLow = float(w.first);
                o.windowHigh = float(w.second);
            }
            if (bitDepth != 8 && bitDepth != 16) throw Error("--bit-depth must be 8 or 16");
            o.bitDepth = bitDepth;
            o.alpha = alpha;
            o.metadata = {{"Software", std::string("splat ") + SPLAT_VERSION_STRING + " (Python)"}};
            py::gil_scoped_release release;
            try {
                writeImage(path, im, o);
            } catch (const Error& e) {
                rethrowFileError(e, path, false);
            }
        },
        py::arg("path"), py::arg("image"), py::kw_only(), py::arg("window") = py::none(),
        py::arg("bit_depth") = 8, py::arg("alpha") = false,
        "Writes .exr/.tif (float RGBA as given) or .png/.gif/.jpg (display values: sRGB, or "
        "the grey window (low, high) of the red channel for mip/xray images), atomically.");
    m.def(
        "default_window",
        [](const py::array& image) {
            const Image im = fromArray(image, "default_window");
            return defaultWindow({&im});
        },
        py::arg("image"), "The display window the CLI uses for mip/xray 8-bit output.");
    m.def(
        "_compare",
        [](const py::array& test, const py::array& reference, bool flip, double ppd, bool srgb) {
            const Image a = fromArray(test, "compare"), b = fromArray(reference, "compare");
            ImageMetrics mt;
            double f = NAN;
            if (!std::isfinite(ppd) || !(ppd > 0)) throw Error("compare: --ppd must be > 0");
            {
                py::gil_scoped_release release;
                mt = compareImages(a, b);
                if (flip)
                    f = srgb ? flipMeanSrgb(a, b, flipOptions(ppd))
                             : flipMean(a, b, flipOptions(ppd));
            }
            py::dict d = metricsDict(mt);
            d["flip"] = f;
            return d;
        },
        py::arg("test"), py::arg("reference"), py::arg("flip"), py::arg("ppd"), py::arg("srgb"));
    m.def(
        "flip_map",
        [](const py::array& test, const py::array& reference, double ppd) {
            const Image a = fromArray(test, "flip_map"), b = fromArray(reference, "flip_map");
            std::vector<float> map;
            {
                py::gil_scoped_release release;
                map = flipErrorMap(a, b, flipOptions(ppd));
            }
            py::array_t<float> out({py::ssize_t(a.height), py::ssize_t(a.width)});
            std::copy(map.begin(), map.end(), out.mutable_data());
            return out;
        },
        py::arg("test"), py::arg("reference"),
        py::arg("ppd") = flipPixelsPerDegree(0.7, 0.7, 3840.0),
        "Per-pixel LDR-FLIP (Andersson et al. 2020) between two linear RGB images, H x W.");
    m.def(
        "write_heatmap",
        [](const std::string& path, const py::array& test, const py::array& reference,
           double scale) {
            const Image a = fromArray(test, "write_heatmap"),
                        b = fromArray(reference, "write_heatmap");
            py::gil_scoped_release release;
            try {
                writeHeatmap(path, a, b, scale);
            } catch (const Error& e) {
                rethrowFileError(e, path, false);
            }
        },
        py::arg("path"), py::arg("test"), py::arg("reference"), py::arg("scale") = 0.0,
        "|test - reference| as an inferno heat map (as `splat compare --heatmap`).");
}

}  // namespace splat::python
