// splat.Gaussians, splat.load_gaussians and splat.render_gaussians (splat/gaussians.h): 3D
// Gaussian Splatting scenes from NumPy arrays or .ply files, rendered with the GIL released.
#include <cstring>
#include <utility>

#include "py_common.h"
#include "splat/gaussian_popping.h"
#include "splat/gaussians.h"

namespace splat::python {

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
using Float32C = py::array_t<float, py::array::c_style>;

/// Keeps a NumPy array alive for the scene's borrowed arrays; released with the GIL held
/// (the last copy of a scene may go in a thread that released it).
std::shared_ptr<const void> keepAlive(const py::array& a) {
    return std::shared_ptr<const void>(new py::object(a), [](const void* p) {
        py::gil_scoped_acquire gil;
        delete static_cast<const py::object*>(p);
    });
}

/// `a` as `count` values of T (T = `width` floats): borrowed where the array is float32 and
/// C-contiguous, else converted and copied. Returns whether it was borrowed.
template <class T>
bool viewOrCopy(const py::array& a, std::size_t count, GaussianArray<T>& out) {
    static_assert(sizeof(T) % sizeof(float) == 0);
    if (Float32C::check_(a)) {
        out.borrow(reinterpret_cast<const T*>(a.data()), count, keepAlive(a));
        return true;
    }
    const FloatArray f = FloatArray::ensure(a);
    if (!f) throw Error("Gaussians: the arrays must hold numbers");
    out.resize(count);
    std::memcpy(out.data(), f.data(), count * sizeof(T));
    return false;
}

/// Throws unless `a` has shape `shape` (-1: any, the first dimension must be n).
void checkShape(const py::array& a, std::initializer_list<py::ssize_t> shape, const char* what) {
    bool ok = std::size_t(a.ndim()) == shape.size();
    std::size_t d = 0;
    for (py::ssize_t s : shape) {
        if (ok && s >= 0 && a.shape(d) != s) ok = false;
        ++d;
    }
    if (!ok) throw Error(std::string("Gaussians: ") + what);
}

/// Quaternions of unit length to float precision are read as they are; others are
/// normalised (into an owned copy).
void normaliseRotations(GaussianArray<glm::vec4>& rotations) {
    bool unit = true;
    for (const glm::vec4& q : std::as_const(rotations))  // reading: a borrowed array stays so
        unit = unit && std::abs(glm::length(q) - 1.0f) <= 1e-6f;
    if (unit) return;
    for (glm::vec4& q : rotations) {
        const float len = glm::length(q);
        if (!(len > 0)) throw Error("Gaussians: a rotation quaternion is zero");
        q /= len;
    }
}

/// `o` as a NumPy array (lists and other sequences converted).
py::array asArray(const py::object& o, const char* what) {
    py::array a = py::array::ensure(o);
    if (!a) throw Error(std::string("Gaussians: ") + what + " is not an array of numbers");
    return a;
}

GaussianScene fromObjects(const py::object& meansObj, const py::object& scalesObj,
                          const py::object& rotationsObj, const py::object& opacitiesObj,
                          const py::object& shObj) {
    const py::array means = asArray(meansObj, "means"), scales = asArray(scalesObj, "scales"),
                    rotations = asArray(rotationsObj, "rotations"),
                    opacities = asArray(opacitiesObj, "opacities"), sh = asArray(shObj, "sh");
    checkShape(means, {-1, 3}, "means must have shape (N, 3)");
    const py::ssize_t n = means.shape(0);
    checkShape(scales, {n, 3}, "scales must have shape (N, 3) with N the number of means");
    checkShape(rotations, {n, 4},
               "rotations (w, x, y, z) must have shape (N, 4) with N the number of means");
    checkShape(opacities, {n}, "opacities must have shape (N,)");
    checkShape(sh, {n, -1, 3}, "sh must have shape (N, K, 3), K = 1, 4, 9 or 16");
    const int k = int(sh.shape(1));
    GaussianScene s;
    s.shDegree = k == 1 ? 0 : k == 4 ? 1 : k == 9 ? 2 : k == 16 ? 3 : -1;
    if (s.shDegree < 0) throw Error("Gaussians: sh must have K = 1, 4, 9 or 16 coefficients");
    const std::size_t count = std::size_t(n);
    viewOrCopy(means, count, s.means);
    viewOrCopy(scales, count, s.scales);
    viewOrCopy(rotations, count, s.rotations);
    viewOrCopy(opacities, count, s.opacities);
    viewOrCopy(sh, count * std::size_t(k) * 3, s.sh);
    normaliseRotations(s.rotations);
    s.source = "NumPy arrays";
    s.validate();
    return s;
}

template <class T>
py::array_t<float> rows(const GaussianArray<T>& v, py::ssize_t width) {
    py::array_t<float> a({py::ssize_t(v.size()), width});
    std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
    return a;
}

/// The text of keyword `name`, taken out of `k` ("" when absent).
std::string takeKeyword(Keywords& k, const std::string& name) {
    std::string text;
    for (auto it = k.begin(); it != k.end();)
        if (it->first == name) {
            text = it->second;
            it = k.erase(it);
        } else {
            ++it;
        }
    return text;
}

bool hasKeyword(const Keywords& k, const std::string& name) {
    for (const auto& kv : k)
        if (kv.first == name) return true;
    return false;
}

/// The Gaussian renderers' options from a frame's keywords (slab when given, ref_tolerance,
/// threads), `view` their camera and threads.
GaussianRenderOptions gaussianOptionsOf(const Keywords& k, const RenderSettings& view) {
    GaussianRenderOptions o;
    o.threads = view.threads;
    o.slab = hasKeyword(k, "slab") ? view.quality.slab : 0;
    o.tolerance = view.quality.referenceTolerance;
    return o;
}

/// splat.render / Scene.render of a Gaussian scene: the render keywords as the CLI's
/// `splat render scene.ply` reads them (renderer 3dgs, 3dgs-pixel, sheet or reference).
py::object renderGaussianFrame(const GaussianScene& scene, Keywords k, const py::object& progress,
                               bool withStats) {
    const std::string renderer = takeKeyword(k, "renderer");
    // The view keywords read as for a volume's sheet renderer, the one that takes slab=.
    Keywords parse = k;
    parse.emplace_back("renderer", "sheet");
    const RenderSettings view = parseRenderSettings(parse, "", nullptr, true);
    GaussianRenderOptions o = gaussianOptionsOf(k, view);
    o.renderer = parseGaussianRenderer(renderer.empty() ? "3dgs" : renderer);
    CameraParams camera = view.camera;
    if (camera.lookAtSet && std::isnan(camera.lookAt.x)) camera.lookAt = scene.geometry().center();
    Interrupt in(progress);
    RenderStats stats;
    Image image = interruptible(in, [&] {
        const auto t0 = std::chrono::steady_clock::now();
        Image im = renderGaussians(scene, camera, o);
        stats.milliseconds =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        return im;
    });
    py::array_t<float> a = toArray(std::move(image));
    if (!withStats) return a;
    return py::make_tuple(a, statsDict(stats));
}

/// splat.popping of a Gaussian scene (splat/gaussian_popping.h): the sweep keywords as the
/// CLI's, renderers= 3dgs, 3dgs-pixel, sheet, reference (default all four).
PoppingResult poppingGaussians(const GaussianScene& scene, Keywords k, const py::object& progress) {
    const std::string renderers = takeKeyword(k, "renderers");
    takeKeyword(k, "truth");  // the Gaussian reference is point-sampled
    OptionValues sweepValues(kSweepOptions);
    Sweep sweep;
    PoppingOptions o;
    const RenderSettings view =
        parseRenderSettings(k, "", nullptr, false, kSweepOptions,
                            [&](const OptionValues& values, const RenderSettings& s) {
                                sweepValues = values;
                                poppingFrom(values, s, sweep, o);
                            });
    const std::vector<GaussianRenderer> list =
        parseGaussianRenderers(renderers.empty() ? "3dgs,3dgs-pixel,sheet,reference" : renderers);
    const GaussianRenderOptions g = gaussianOptionsOf(k, view);
    Interrupt in(progress);
    o.progress = in.progress();
    return interruptible(in, [&] {
        const std::string& path = sweepValues.text("path");
        if (path.empty()) return analyzeGaussianPopping(scene, sweep, list, g, o);
        return analyzeGaussianPopping(
            scene, CameraPath::fromJson(path, view.camera, int(sweepValues.integer("frames"))),
            list, g, o);
    });
}

}  // namespace

void bindGaussians(py::module_& m) {
    py::class_<GaussianScene>(m, "Gaussians",
                              "A 3D Gaussian Splatting scene (splat/gaussians.h): means, scales "
                              "(standard deviations), unit quaternions (w, x, y, z), opacities in "
                              "[0, 1] and SH coefficients (N, K, 3).")
        .def(py::init(&fromObjects), py::arg("means"), py::arg("scales"), py::arg("rotations"),
             py::arg("opacities"), py::arg("sh"))
        .def("__len__", &GaussianScene::size)
        .def_property_readonly(
            "borrowed",
            [](const GaussianScene& s) {
                return s.means.borrowed() && s.scales.borrowed() && s.rotations.borrowed() &&
                       s.opacities.borrowed() && s.sh.borrowed();
            },
            "True when the scene reads the NumPy arrays it was made from (float32, "
            "C-contiguous, unit quaternions) without a copy.")
        .def_property_readonly("sh_degree", [](const GaussianScene& s) { return s.shDegree; })
        .def_property_readonly("source", [](const GaussianScene& s) { return s.source; })
        .def_property_readonly("means", [](const GaussianScene& s) { return rows(s.means, 3); })
        .def_property_readonly("scales", [](const GaussianScene& s) { return rows(s.scales, 3); })
        .def_property_readonly("rotations",
                               [](const GaussianScene& s) { return rows(s.rotations, 4); })
        .def_property_readonly("opacities",
                               [](const GaussianScene& s) {
                                   py::array_t<float> a(py::ssize_t(s.size()));
                                   std::copy(s.opacities.begin(), s.opacities.end(),
                                             a.mutable_data());
                                   return a;
                               })
        .def_property_readonly("sh",
                               [](const GaussianScene& s) {
                                   py::array_t<float> a({py::ssize_t(s.size()),
                                                         py::ssize_t(s.shCount()), py::ssize_t(3)});
                                   std::copy(s.sh.begin(), s.sh.end(), a.mutable_data());
                                   return a;
                               })
        .def(
            "write",
            [](const GaussianScene& s, const std::string& path) {
                try {
                    writeGaussians(s, path);
                } catch (const Error& e) {
                    rethrowFileError(e, path, false);
                }
            },
            py::arg("path"), "Writes the scene as a 3DGS .ply (binary_little_endian).");
    m.def(
        "load_gaussians",
        [](const std::string& path) {
            try {
                return openGaussians(path);
            } catch (const Error& e) {
                rethrowFileError(e, path, true);
            }
        },
        py::arg("path"),
        "A 3DGS .ply scene, or a generated one: 'gaussians:pop', 'gaussians:random:N[:SEED]'.");
    m.def("_render_gaussians", &renderGaussianFrame, py::arg("scene"), py::arg("options"),
          py::arg("progress"), py::arg("return_stats"));
    m.def("_popping_gaussians", &poppingGaussians, py::arg("scene"), py::arg("options"),
          py::arg("progress"));
    m.def(
        "render_gaussians",
        [](const GaussianScene& scene, const std::string& renderer, int width, int height,
           double azimuth, double elevation, const std::string& projection, double pixelSize,
           double fov, double slab, double refTolerance, int threads) {
            GaussianRenderOptions o;
            o.renderer = parseGaussianRenderer(renderer);
            o.slab = slab;
            o.tolerance = refTolerance;
            o.threads = threads;
            CameraParams c;
            c.width = width;
            c.height = height;
            c.azimuthDeg = azimuth;
            c.elevationDeg = elevation;
            if (projection != "ortho" && projection != "perspective")
                throw Error("projection must be ortho or perspective");
            c.projection =
                projection == "perspective" ? Projection::Perspective : Projection::Orthographic;
            c.pixelSize = pixelSize;
            c.fovDeg = fov;
            Image image;
            {
                py::gil_scoped_release release;
                image = renderGaussians(scene, c, o);
            }
            return toArray(std::move(image));
        },
        py::arg("scene"), py::kw_only(), py::arg("renderer") = "3dgs", py::arg("width") = 512,
        py::arg("height") = 512, py::arg("azimuth") = 0.0, py::arg("elevation") = 0.0,
        py::arg("projection") = "ortho", py::arg("pixel_size") = 0.0, py::arg("fov") = 30.0,
        py::arg("slab") = 0.0, py::arg("ref_tolerance") = 1e-4, py::arg("threads") = 0,
        "One frame of a Gaussian scene, H x W x 4 premultiplied RGBA: renderer 3dgs, "
        "3dgs-pixel, sheet or reference (as splat render's --renderer).");
}

}  // namespace splat::python
