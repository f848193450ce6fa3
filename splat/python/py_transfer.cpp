// splat.TransferFunction: presets, the project's and ParaView's JSON files, or control points
// from NumPy ([value, r, g, b, a] rows). Passed as tf= to render, it is read exactly like a
// scene file's inline "tf" (the project's JSON), so the CLI's rules apply unchanged.
#include <nlohmann/json.hpp>

#include "py_common.h"
#include "splat/transfer.h"

namespace splat::python {

namespace {

TransferFunction fromPoints(const py::object& pointsObj, bool normalized, double unitDistance,
                            const py::object& mode, const std::string& name) {
    py::array_t<double, py::array::c_style | py::array::forcecast> p;
    try {
        p = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(pointsObj);
    } catch (const py::error_already_set&) {
    }
    if (!p || p.ndim() != 2 || p.shape(1) != 5 || p.shape(0) < 1)
        throw Error("TransferFunction: points must be an N x 5 array of [value, r, g, b, a] rows");
    TransferFunction tf;
    tf.name = name;
    tf.normalized = normalized;
    tf.unitDistance = unitDistance;
    if (!mode.is_none()) tf.mode = parseMode(mode.cast<std::string>());
    auto a = p.unchecked<2>();
    for (py::ssize_t i = 0; i < a.shape(0); ++i)
        tf.points.push_back(TransferPoint{
            float(a(i, 0)),
            glm::vec4(float(a(i, 1)), float(a(i, 2)), float(a(i, 3)), float(a(i, 4)))});
    tf.validate("TransferFunction");
    return tf;
}

py::array_t<float> pointsArray(const TransferFunction& tf) {
    py::array_t<float> out({py::ssize_t(tf.points.size()), py::ssize_t(5)});
    auto w = out.mutable_unchecked<2>();
    for (std::size_t i = 0; i < tf.points.size(); ++i) {
        w(i, 0) = tf.points[i].value;
        for (int c = 0; c < 4; ++c) w(i, c + 1) = tf.points[i].rgba[c];
    }
    return out;
}

}  // namespace

std::string transferJson(const TransferFunction& tf) {
    nlohmann::json j;
    j["domain"] = tf.normalized ? "normalized" : "absolute";
    j["unit_distance"] = tf.unitDistance;
    j["name"] = tf.name;
    if (tf.mode) j["mode"] = toString(*tf.mode);
    j["points"] = nlohmann::json::array();
    for (const TransferPoint& p : tf.points)
        j["points"].push_back({p.value, p.rgba.r, p.rgba.g, p.rgba.b, p.rgba.a});
    return j.dump();
}

void bindTransfer(py::module_& m) {
    static const std::string presetDoc = [] {
        std::string s = "A preset: ";
        for (const std::string& n : TransferFunction::presetNames())
            s += (s.size() > 10 ? ", " : "") + n;
        return s;
    }();
    py::class_<TransferFunction>(m, "TransferFunction", R"doc(
Piecewise-linear colour and opacity over density (splat/transfer.h).

TransferFunction(points, *, normalized=False, unit_distance=1.0, mode=None, name='custom')

points: N x 5 array of [value, r, g, b, a] rows, values non-decreasing, colour and opacity in
  [0, 1]; opacity per unit_distance world units. normalized=True: values are fractions of the
  volume's [min, max]. mode: the render mode the function is made for ('mip', 'xray', ...).
Also TransferFunction.preset(name), .from_json(path) (the project's or ParaView's JSON,
'path#Name' picks one ParaView preset) and .load(preset name or path), as --tf takes them.
)doc")
        .def(py::init(&fromPoints), py::arg("points"), py::kw_only(), py::arg("normalized") = false,
             py::arg("unit_distance") = 1.0, py::arg("mode") = py::none(),
             py::arg("name") = "custom")
        .def_static("preset", &TransferFunction::preset, py::arg("name"), presetDoc.c_str())
        .def_static("presets", &TransferFunction::presetNames, "The preset names.")
        .def_static(
            "from_json",
            [](const std::string& path) {
                try {
                    return TransferFunction::fromJson(path);
                } catch (const Error& e) {
                    rethrowFileError(e, path.substr(0, path.find('#')), true);
                }
            },
            py::arg("path"), "The project's JSON or ParaView's colour-map JSON ('file.json#Name').")
        .def_static(
            "load",
            [](const std::string& what) {
                try {
                    return TransferFunction::load(what);
                } catch (const Error& e) {
                    if (what.ends_with(".json") || what.find(".json#") != std::string::npos)
                        rethrowFileError(e, what.substr(0, what.find('#')), true);
                    throw;
                }
            },
            py::arg("name_or_path"), "A preset name or a JSON path, as --tf takes it.")
        .def_readwrite("name", &TransferFunction::name)
        .def_property_readonly("points", &pointsArray, "N x 5 array of [value, r, g, b, a].")
        .def_readonly("normalized", &TransferFunction::normalized,
                      "True: values are fractions of the volume's [min, max].")
        .def_readonly("unit_distance", &TransferFunction::unitDistance,
                      "World length the opacities refer to.")
        .def_property_readonly(
            "mode",
            [](const TransferFunction& tf) -> py::object {
                if (!tf.mode) return py::none();
                return py::str(toString(*tf.mode));
            },
            "The render mode the function carries, or None.")
        .def(
            "sample",
            [](const TransferFunction& tf, const py::array_t<float, py::array::forcecast>& d) {
                py::array_t<float> out;
                std::vector<py::ssize_t> shape(d.shape(), d.shape() + d.ndim());
                shape.push_back(4);
                out = py::array_t<float>(shape);
                const float* in = d.data();
                float* o = out.mutable_data();
                const py::ssize_t n = d.size();
                auto flat =
                    py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(d);
                in = flat.data();
                for (py::ssize_t i = 0; i < n; ++i) {
                    const glm::vec4 c = tf.sample(in[i]);
                    for (int k = 0; k < 4; ++k) o[4 * i + k] = c[k];
                }
                return out;
            },
            py::arg("values"), "Colour and opacity (..., 4) at densities `values`.")
        .def(
            "extinction",
            [](const TransferFunction& tf, double d) { return tf.extinction(float(d)); },
            py::arg("value"), "Extinction per world unit at density `value`.")
        .def("resolved", &TransferFunction::resolved, py::arg("low"), py::arg("high"),
             "Normalized control points mapped onto [low, high].")
        .def("rescaled_to_data", &TransferFunction::rescaledToData,
             "The same function on the normalized domain (--tf-rescale).")
        .def("to_json", &transferJson,
             "The project's JSON text (TransferFunction.from_json reads it).")
        .def("__repr__", [](const TransferFunction& tf) {
            return "splat.TransferFunction('" + tf.name + "', " + std::to_string(tf.points.size()) +
                   " points, " + (tf.normalized ? "normalized" : "absolute") + ")";
        });
}

}  // namespace splat::python
