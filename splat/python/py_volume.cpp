// splat.Volume: a 3-D NumPy array [z, y, x] (x fastest in memory, as scikit-image and
// SimpleITK index) with spacing and origin given x, y, z; splat.load for every format the CLI
// reads; splat.from_nibabel's affine step. docs/python.md states the conversions.
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>

#include "py_common.h"
#include "splat/orientation.h"
#include "splat/synthetic.h"
#include "splat/volume_io.h"

namespace splat::python {

namespace {

glm::dvec3 vec3Of(const py::object& o, const char* what) {
    std::vector<double> v;
    try {
        v = o.cast<std::vector<double>>();
    } catch (const py::cast_error&) {
        throw Error(std::string("splat.Volume: ") + what + " must be 3 numbers (x, y, z)");
    }
    if (v.size() != 3)
        throw Error(std::string("splat.Volume: ") + what + " must be 3 numbers (x, y, z), got " +
                    std::to_string(v.size()));
    for (double x : v)
        if (!std::isfinite(x))
            throw Error(std::string("splat.Volume: ") + what + " must be finite");
    return {v[0], v[1], v[2]};
}

std::string shapeText(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

/// The array's samples as float32 in [z, y, x] order (x fastest): `order` "zyx" takes the
/// array as it is, "xyz" (nibabel's) its transpose. Real dtypes other than float32 are
/// converted (float64 rounds to nearest; integers exactly up to 2^24); anything else refused.
py::array_t<float, py::array::c_style> zyxFloat(const py::array& a, const std::string& order) {
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b')
        throw Error("splat.Volume: dtype " + std::string(py::str(a.dtype())) +
                    " is not a real number type (use float32, or an integer or float type "
                    "converted to float32)");
    py::array view = order == "zyx" ? a : py::array(a.attr("transpose")());
    // forcecast: a converted copy when the dtype or the layout differ; the array itself (no
    // copy) when it is float32 and C-contiguous.
    return py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(view);
}

/// The first non-finite sample and their count (0: none), read through Volume::value
/// whatever the storage. Runs without the GIL.
std::pair<std::size_t, std::size_t> nonFinite(const Volume& v) {
    std::size_t count = 0, first = 0;
    for (std::size_t n = 0, total = v.voxelCount(); n < total; ++n)
        if (!std::isfinite(v.value(n))) {
            if (!count) first = n;
            ++count;
        }
    return {count, first};
}

/// Refuses NaN/Inf samples (policy "error", as the loaders' --nan-policy) or, in an owned
/// float volume, replaces them by 0 (policy "zero"; the count goes to the note).
void applyNanPolicy(Volume& v, const std::string& policy, std::size_t count, std::size_t first) {
    if (!count) return;
    const std::size_t nx = std::size_t(v.dims.x), ny = std::size_t(v.dims.y);
    char where[96];
    std::snprintf(where, sizeof where, "first at [z, y, x] = [%zu, %zu, %zu]", first / (nx * ny),
                  (first / nx) % ny, first % nx);
    if (policy != "zero")
        throw Error("splat.Volume: " + std::to_string(count) + " NaN/Inf samples (" + where +
                    "); nan_policy='zero' replaces them by 0");
    for (float& d : v.data)
        if (!std::isfinite(d)) d = 0.0f;
    if (!v.note.empty()) v.note += "; ";
    v.note += std::to_string(count) + " NaN/Inf samples replaced by 0 (" + where + ")";
}

/// The sample types a volume can borrow; nullopt for the others.
std::optional<SampleType> borrowableType(const py::array& a) {
    const py::dtype d = a.dtype();
    if (!d.attr("isnative").cast<bool>()) return std::nullopt;  // byte-swapped: converted
    const char kind = d.kind();
    const py::ssize_t size = d.itemsize();
    if (kind == 'f' && size == 4) return SampleType::Float32;
    if (kind == 'u' && size == 1) return SampleType::UInt8;
    if (kind == 'i' && size == 2) return SampleType::Int16;
    if (kind == 'u' && size == 2) return SampleType::UInt16;
    return std::nullopt;
}

/// Holds a Python object for the library (Volume keepAlive): released with the GIL taken,
/// whichever thread drops the last reference.
std::shared_ptr<const void> keepAlive(py::object o) {
    PyObject* p = o.release().ptr();
    return std::shared_ptr<const void>(p, [](const void* q) {
        py::gil_scoped_acquire gil;
        Py_DECREF(static_cast<PyObject*>(const_cast<void*>(q)));
    });
}

void checkPolicy(const std::string& policy, const std::string& order) {
    if (policy != "error" && policy != "zero")
        throw Error("splat.Volume: nan_policy '" + policy + "': expected 'error' or 'zero'");
    if (order != "zyx" && order != "xyz")
        throw Error("splat.Volume: order '" + order +
                    "': expected 'zyx' (array[z, y, x], scikit-image, SimpleITK) or 'xyz' "
                    "(array[x, y, z], nibabel)");
}

/// dims (x, y, z) of a 3-D array in `order`, checked against the library's limits.
glm::ivec3 dimsOf(const py::array& a, const std::string& order) {
    if (a.ndim() != 3)
        throw Error("splat.Volume: the array must be 3-D (" +
                    std::string(order == "zyx" ? "[z, y, x]" : "[x, y, z]") + "), got " +
                    std::to_string(a.ndim()) + "-D shape " + shapeText(a));
    glm::ivec3 d;
    for (int axis = 0; axis < 3; ++axis) {
        const py::ssize_t n = a.shape(order == "zyx" ? 2 - axis : axis);
        if (n < 1)
            throw Error("splat.Volume: the array has no samples (shape " + shapeText(a) + ")");
        if (n > 65535)
            throw Error("splat.Volume: shape " + shapeText(a) +
                        " has an axis longer than 65535 samples (the splat index limit)");
        d[axis] = int(n);
    }
    checkedVoxelCount(d, "splat.Volume array");
    return d;
}

/// The volume of a 3-D array: borrowed (no copy) when its [z, y, x] view is float32,
/// uint8, int16 or uint16, C-contiguous and aligned (and `allowBorrow`), else a float32 copy.
Volume volumeFromArray(const py::array& input, const glm::dvec3& spacing, const glm::dvec3& origin,
                       const std::string& order, const std::string& nanPolicy,
                       bool allowBorrow = true) {
    checkPolicy(nanPolicy, order);
    const glm::ivec3 dims = dimsOf(input, order);
    for (int a = 0; a < 3; ++a)
        if (!(spacing[a] > 0) || spacing[a] > 1e12)
            throw Error("splat.Volume: spacing must be finite and > 0 on every axis");
    const std::string source = "NumPy array " + std::string(py::str(input.dtype())) + " " +
                               shapeText(input) + (order == "xyz" ? " [x, y, z]" : " [z, y, x]");
    py::array zyx = order == "zyx" ? input : py::array(input.attr("transpose")());
    const auto type = borrowableType(zyx);
    const bool contiguous = (zyx.flags() & py::array::c_style) &&
                            (zyx.flags() & py::detail::npy_api::NPY_ARRAY_ALIGNED_);
    if (allowBorrow && type && contiguous) {
        Volume v = Volume::borrow(zyx.data(), *type, dims, spacing, origin, keepAlive(zyx));
        v.source = source;
        std::pair<std::size_t, std::size_t> bad;
        {
            py::gil_scoped_release release;
            bad = nonFinite(v);
        }
        if (bad.first == 0) return v;
        if (nanPolicy != "zero") applyNanPolicy(v, nanPolicy, bad.first, bad.second);
        // nan_policy='zero' never writes into the caller's array: a float copy instead.
    }
    py::array_t<float, py::array::c_style> samples = zyxFloat(input, order);
    Volume v = makeVolume(dims, spacing, "splat.Volume array");
    v.origin = origin;
    v.source = source;
    const float* src = samples.data();
    {
        py::gil_scoped_release release;
        std::memcpy(v.data.data(), src, v.data.size() * sizeof(float));
        const auto [count, first] = nonFinite(v);
        applyNanPolicy(v, nanPolicy, count, first);
    }
    return v;
}

void setBackground(Volume& v, const py::object& background) {
    if (background.is_none()) {
        py::gil_scoped_release release;
        v.background = backgroundFromFaces(v);
        v.backgroundSource = "median of the outer faces";
        return;
    }
    const double b = background.cast<double>();
    if (!(std::abs(b) <= 3.0e38))
        throw Error("splat.Volume: background_value must be a finite number");
    v.background = float(b);
    v.backgroundSource = "background_value";
}

PyVolume share(Volume&& v) { return PyVolume{std::make_shared<const Volume>(std::move(v))}; }

py::tuple xyz(const glm::dvec3& v) { return py::make_tuple(v.x, v.y, v.z); }

std::vector<std::string> notesOf(const Volume& v) {
    std::vector<std::string> out;
    std::string n = v.note;
    for (std::size_t at; (at = n.find("; ")) != std::string::npos;) {
        out.push_back(n.substr(0, at));
        n.erase(0, at + 2);
    }
    if (!n.empty()) out.push_back(n);
    return out;
}

/// splat.Volume: the samples as a NumPy view, the geometry, the background.
void bindVolumeClass(py::module_& m) {
    py::class_<PyVolume>(m, "Volume", R"doc(
A scalar volume: samples on a regular grid, world position x = origin + spacing * (i, j, k).

Volume(array, spacing=(1, 1, 1), origin=(0, 0, 0), *, order='zyx', background_value=None,
       nan_policy='error')

array: 3-D NumPy array (or anything numpy.asarray accepts) indexed [z, y, x] as in
  scikit-image and SimpleITK (x fastest in memory); order='xyz' takes nibabel's [x, y, z]
  (its transpose). float32 C-contiguous data are used as they are; other real dtypes
  (float64, int8..uint32, bool) and non-contiguous arrays are converted to float32 (a copy).
spacing, origin: world units, given (x, y, z) whatever the index order.
background_value: the field's value where nothing is (default: the median of the outer faces,
  as splat load does). nan_policy: 'error' refuses NaN/Inf samples, 'zero' replaces them.
)doc")
        .def(py::init([](const py::object& array, const py::object& spacing,
                         const py::object& origin, const std::string& order,
                         const py::object& background, const std::string& nanPolicy) {
                 py::array a = py::array::ensure(array);
                 if (!a) throw Error("splat.Volume: the array is not convertible to a NumPy array");
                 Volume v = volumeFromArray(a, vec3Of(spacing, "spacing"), vec3Of(origin, "origin"),
                                            order, nanPolicy);
                 setBackground(v, background);
                 return share(std::move(v));
             }),
             py::arg("array"), py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0),
             py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0), py::kw_only(),
             py::arg("order") = "zyx", py::arg("background_value") = py::none(),
             py::arg("nan_policy") = "error")
        .def_property_readonly(
            "array",
            [](const py::object& self) {
                const Volume& v = *self.cast<const PyVolume&>().volume;
                py::dtype type = py::dtype(sampleTypeName(v.sampleType()));
                py::array a(type,
                            {py::ssize_t(v.dims.z), py::ssize_t(v.dims.y), py::ssize_t(v.dims.x)},
                            v.sampleData(), self);
                a.attr("flags").attr("writeable") = false;
                return a;
            },
            "The samples as a read-only NumPy view [z, y, x] (no copy): the wrapped array's "
            "memory for a borrowed volume, with its dtype.")
        .def_property_readonly(
            "shape",
            [](const PyVolume& p) {
                return py::make_tuple(p.volume->dims.z, p.volume->dims.y, p.volume->dims.x);
            },
            "Array shape (z, y, x).")
        .def_property_readonly(
            "dims",
            [](const PyVolume& p) {
                return py::make_tuple(p.volume->dims.x, p.volume->dims.y, p.volume->dims.z);
            },
            "Samples along x, y, z.")
        .def_property_readonly(
            "spacing", [](const PyVolume& p) { return xyz(p.volume->spacing); },
            "World units between samples along x, y, z.")
        .def_property_readonly(
            "origin", [](const PyVolume& p) { return xyz(p.volume->origin); },
            "World position (x, y, z) of sample [0, 0, 0].")
        .def_property_readonly(
            "center", [](const PyVolume& p) { return xyz(p.volume->center()); },
            "World position of the volume centre.")
        .def_property_readonly(
            "orientation",
            [](const PyVolume&) {
                py::array_t<double> r({3, 3});
                auto w = r.mutable_unchecked<2>();
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j) w(i, j) = i == j;
                return r;
            },
            "Direction cosines of the index axes (columns): always the identity, splat volumes "
            "are axis-aligned (files and from_nibabel apply flips and permutations; an oblique "
            "rest is named in notes).")
        .def_property_readonly(
            "affine",
            [](const PyVolume& p) {
                py::array_t<double> r({4, 4});
                auto w = r.mutable_unchecked<2>();
                for (int i = 0; i < 4; ++i)
                    for (int j = 0; j < 4; ++j) w(i, j) = 0;
                for (int i = 0; i < 3; ++i) {
                    w(i, i) = p.volume->spacing[i];
                    w(i, 3) = p.volume->origin[i];
                }
                w(3, 3) = 1;
                return r;
            },
            "4x4 index (i, j, k) = (x, y, z) to world matrix, as nibabel's img.affine.")
        .def_property_readonly(
            "value_range",
            [](const PyVolume& p) {
                VolumeStats s;
                {
                    py::gil_scoped_release release;
                    s = volumeStats(*p.volume, 1);
                }
                return py::make_tuple(s.minValue, s.maxValue);
            },
            "(min, max) of the samples.")
        .def_property_readonly(
            "background_value", [](const PyVolume& p) { return p.volume->background; },
            "The field's value where nothing is (b of docs/design.md).")
        .def_property_readonly(
            "background_source", [](const PyVolume& p) { return p.volume->backgroundSource; },
            "Where background_value came from.")
        .def_property_readonly(
            "source", [](const PyVolume& p) { return p.volume->source; },
            "How the volume was obtained.")
        .def_property_readonly(
            "notes", [](const PyVolume& p) { return notesOf(*p.volume); },
            "What the loader assumed or changed, one line each.")
        .def_property_readonly(
            "dtype",
            [](const PyVolume& p) { return std::string(sampleTypeName(p.volume->sampleType())); },
            "The sample type as stored: float32, or uint8/int16/uint16 for wrapped arrays.")
        .def_property_readonly(
            "borrowed", [](const PyVolume& p) { return p.volume->borrowed(); },
            "True when the samples are the wrapped NumPy array's memory (no copy).")
        .def_property_readonly(
            "nbytes", [](const PyVolume& p) { return p.volume->bytes(); },
            "Bytes the samples take.")
        .def(
            "describe", [](const PyVolume& p) { return describeVolume(*p.volume); },
            "The multi-line description `splat info` prints.")
        .def(
            "save",
            [](const PyVolume& p, const std::string& path) {
                const std::string ext = path.size() > 4 ? path.substr(path.rfind('.')) : "";
                py::gil_scoped_release release;
                try {
                    if (path.ends_with(".nii") || path.ends_with(".nii.gz"))
                        saveNifti(path, *p.volume);
                    else if (path.ends_with(".nrrd"))
                        saveNrrd(path, *p.volume);
                    else if (path.ends_with(".mha") || path.ends_with(".mhd"))
                        saveMetaImage(path, *p.volume);
                    else
                        throw Error(path +
                                    ": unsupported volume type (use .nii, .nii.gz, .nrrd, "
                                    ".mha or .mhd)");
                } catch (const FileFailure&) {
                    throw;
                } catch (const Error& e) {
                    rethrowFileError(e, path, false);
                }
            },
            py::arg("path"), "Writes .nii/.nii.gz, .nrrd or .mha/.mhd (float32), atomically.")
        .def("__repr__", [](const PyVolume& p) {
            const Volume& v = *p.volume;
            std::ostringstream s;
            s << "splat.Volume(shape=(" << v.dims.z << ", " << v.dims.y << ", " << v.dims.x
              << "), spacing=(" << v.spacing.x << ", " << v.spacing.y << ", " << v.spacing.z
              << "), source='" << v.source << "')";
            return s.str();
        });
}

/// splat.load and the other ways to obtain a Volume (synthetic, DICOM series, nibabel).
void bindLoaders(py::module_& m) {
    m.def(
        "_load",
        [](const std::string& spec, const Keywords& options) {
            return share(loadWithOptions(spec, options));
        },
        py::arg("spec"), py::arg("options"));
    m.def("_load_options", &loadOptionTable);
    m.def(
        "_from_affine",
        [](const py::object& array, const py::array_t<double>& affine, const std::string& source,
           const py::object& background, const std::string& nanPolicy) {
            py::array a = py::array::ensure(array);
            if (!a) throw Error("from_nibabel: the data are not convertible to a NumPy array");
            if (affine.ndim() != 2 || affine.shape(0) < 3 || affine.shape(1) != 4)
                throw Error("from_nibabel: the affine must be a 4x4 (or 3x4) matrix");
            auto A = affine.unchecked<2>();
            glm::dmat3 M;
            glm::dvec3 t;
            for (int r = 0; r < 3; ++r) {
                for (int c = 0; c < 3; ++c) M[c][r] = A(r, c);
                t[r] = A(r, 3);
            }
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 4; ++c)
                    if (!std::isfinite(A(r, c)))
                        throw Error("from_nibabel: the affine holds NaN or Inf");
            Volume v;
            if (isAxisAligned(M)) {  // spacing and origin only: the array as it is
                v = volumeFromArray(a, glm::dvec3(M[0][0], M[1][1], M[2][2]), t, "xyz", nanPolicy);
            } else {  // samples move: a float copy, oriented like the loaders do
                v = volumeFromArray(a, glm::dvec3(1.0), glm::dvec3(0.0), "xyz", nanPolicy, false);
                orientVolume(v, M, t, "affine");
            }
            v.source = source;
            setBackground(v, background);
            return share(std::move(v));
        },
        py::arg("array"), py::arg("affine"), py::arg("source"), py::arg("background_value"),
        py::arg("nan_policy"));
    m.def("synthetic_names", &syntheticNames, "Names accepted by synthetic().");
    m.def(
        "list_dicom_series",
        [](const std::string& folder) {
            py::list out;
            for (const DicomSeriesInfo& s : listDicomSeries(folder)) {
                py::dict d;
                d["uid"] = s.uid;
                d["description"] = s.description;
                d["modality"] = s.modality;
                d["series_number"] = s.seriesNumber;
                d["files"] = s.files;
                d["rows"] = s.rows;
                d["columns"] = s.columns;
                out.append(d);
            }
            return out;
        },
        py::arg("folder"), "The DICOM series of a folder (as `splat info FOLDER`), as dicts.");
}

}  // namespace

void bindVolume(py::module_& m) {
    bindVolumeClass(m);
    bindLoaders(m);
}

}  // namespace splat::python
