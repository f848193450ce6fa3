// splat.Gaussians, splat.load_gaussians and splat.render_gaussians (splat/gaussians.h): 3D
// Gaussian Splatting scenes from NumPy arrays or .ply files, rendered with the GIL released.
#include <cstring>

#include "py_common.h"
#include "splat/gaussians.h"

namespace splat::python {

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// Copies an (N, width) float array into `out` (as `count` x `width` floats).
template <class T>
void copyRows(const FloatArray& a, std::size_t n, std::size_t width, const char* what,
              std::vector<T>& out) {
    if (a.ndim() != 2 || std::size_t(a.shape(0)) != n || std::size_t(a.shape(1)) != width)
        throw Error(std::string("Gaussians: ") + what + " must have shape (N, " +
                    std::to_string(width) + ") with N the number of means");
    out.resize(n);
    std::memcpy(out.data(), a.data(), n * width * sizeof(float));
}

GaussianScene fromArrays(const FloatArray& means, const FloatArray& scales,
                         const FloatArray& rotations, const FloatArray& opacities,
                         const FloatArray& sh) {
    if (means.ndim() != 2 || means.shape(1) != 3)
        throw Error("Gaussians: means must have shape (N, 3)");
    const std::size_t n = std::size_t(means.shape(0));
    GaussianScene s;
    copyRows(means, n, 3, "means", s.means);
    copyRows(scales, n, 3, "scales", s.scales);
    copyRows(rotations, n, 4, "rotations (w, x, y, z)", s.rotations);
    if (opacities.ndim() != 1 || std::size_t(opacities.shape(0)) != n)
        throw Error("Gaussians: opacities must have shape (N,)");
    s.opacities.assign(opacities.data(), opacities.data() + n);
    if (sh.ndim() != 3 || std::size_t(sh.shape(0)) != n || sh.shape(2) != 3)
        throw Error("Gaussians: sh must have shape (N, K, 3), K = 1, 4, 9 or 16");
    const int k = int(sh.shape(1));
    s.shDegree = k == 1 ? 0 : k == 4 ? 1 : k == 9 ? 2 : k == 16 ? 3 : -1;
    if (s.shDegree < 0) throw Error("Gaussians: sh must have K = 1, 4, 9 or 16 coefficients");
    s.sh.assign(sh.data(), sh.data() + n * std::size_t(k) * 3);
    for (auto& q : s.rotations) {
        const float len = glm::length(q);
        if (!(len > 0)) throw Error("Gaussians: a rotation quaternion is zero");
        q /= len;
    }
    s.source = "NumPy arrays";
    s.validate();
    return s;
}

template <class T>
py::array_t<float> rows(const std::vector<T>& v, py::ssize_t width) {
    py::array_t<float> a({py::ssize_t(v.size()), width});
    std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
    return a;
}

}  // namespace

void bindGaussians(py::module_& m) {
    py::class_<GaussianScene>(m, "Gaussians",
                              "A 3D Gaussian Splatting scene (splat/gaussians.h): means, scales "
                              "(standard deviations), unit quaternions (w, x, y, z), opacities in "
                              "[0, 1] and SH coefficients (N, K, 3).")
        .def(py::init(&fromArrays), py::arg("means"), py::arg("scales"), py::arg("rotations"),
             py::arg("opacities"), py::arg("sh"))
        .def("__len__", &GaussianScene::size)
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
