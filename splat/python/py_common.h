#pragma once
// What every binding file of the Python module shares (docs/python.md): the exception
// types, the long-call runner that releases the GIL and turns Ctrl-C into cancellation, and
// the keyword-argument reader (py_options.cpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "splat/error.h"
#include "splat/image.h"
#include "splat/options.h"
#include "splat/scene.h"
#include "splat/settings.h"
#include "splat/volume.h"

namespace py = pybind11;

namespace splat::python {

/// A failure to read or write a file at the OS level (missing, unreadable, unwritable):
/// raised in Python as splat.FileError (an OSError). Other splat::Errors become
/// splat.InputError (a ValueError), splat::Cancelled splat.Cancelled.
class FileFailure : public Error {
  public:
    explicit FileFailure(const std::string& m) : Error(m) {}
};

/// Rethrows `e` as FileFailure when it is about the file `path` itself: the file is missing,
/// or the message reports an OS error (cannot open/read/write, permission, no such file).
[[noreturn]] void rethrowFileError(const Error& e, const std::string& path, bool reading);

/// One long call's cancellation state: the flag every ProgressFn reads, the Python progress
/// callable (borrowed: the call's arguments keep it alive), and what stopped the call.
struct Interrupt {
    explicit Interrupt(py::object progress = py::none());
    std::atomic<bool> stop{false};
    PyObject* callback = nullptr;      ///< null: none
    bool byCallback = false;           ///< the callable returned False
    std::exception_ptr callbackError;  ///< the callable raised
    std::exception_ptr signalError;    ///< KeyboardInterrupt (or another signal handler's)
    /// A ProgressFn for the library: calls the Python callable (GIL taken) and returns false
    /// once the call is to stop. Holds a reference to *this: use it within the call.
    ProgressFn progress();
};

/// Cancellation of every frame rendered from one Scene (through its settings' ProgressFn,
/// which sequences and analyses use): long calls on the Scene raise `stop` while they run.
struct SceneCancel {
    std::atomic<int> stop{0};
};

/// Runs `work` (a long library call, no Python objects touched) on its own thread with the
/// GIL released; the calling thread wakes every 20 ms to run Python's signal handlers, so
/// that Ctrl-C sets `in.stop`, the library's progress returns false, the call throws
/// splat::Cancelled and KeyboardInterrupt is raised here. `scene`: also stops frames that
/// read the Scene's own progress.
void runInterruptible(Interrupt& in, const std::function<void()>& work,
                      SceneCancel* scene = nullptr);

template <class F>
auto interruptible(Interrupt& in, F&& work, SceneCancel* scene = nullptr) -> decltype(work()) {
    using R = decltype(work());
    if constexpr (std::is_void_v<R>) {
        runInterruptible(in, work, scene);
    } else {
        std::optional<R> result;
        runInterruptible(
            in, [&] { result.emplace(work()); }, scene);
        return std::move(*result);
    }
}

// ---- keyword arguments (py_options.cpp) ---------------------------------------------

/// Keyword arguments as (long option name, text) pairs, built by splat/__init__.py from
/// keyword arguments (("tf", "ct-bone"), ("size", "512x512"), ("shade", "true"), ...).
using Keywords = std::vector<std::pair<std::string, std::string>>;
/// (keyword, flag, help, default) per option, for docstrings and the stub test.
using OptionTableRows = std::vector<std::tuple<std::string, std::string, std::string, std::string>>;

/// Render settings from the rendering options of the option table (splat/options.h);
/// `tfJson` a transfer function given as an object (the project's JSON; empty: none), read
/// like a scene file's inline "tf". With `volume`, the data-dependent defaults (ct-hu for CT
/// in Hounsfield units, the free camera's target). Errors: splat::OptionError with the
/// command line's message. `extraSets`: a command's own options taken with them
/// (splat.popping's sweep, kSweepOptions); `readExtra` reads them once the render settings
/// are parsed.
RenderSettings parseRenderSettings(
    const Keywords& keywords, const std::string& tfJson, const Volume* volume, bool oneRenderer,
    unsigned extraSets = 0,
    const std::function<void(const OptionValues&, const RenderSettings&)>& readExtra = {});

OptionTableRows renderOptionTable();
/// Loads `spec` with the volume options.
Volume loadWithOptions(const std::string& spec, const Keywords& keywords);
OptionTableRows loadOptionTable();
OptionTableRows poppingOptionTable();
/// A scene file read by the library (splat/scene_file.h): its command; (keyword, texts, object
/// JSON) per option of the table and "volume"; the keys of other commands.
using SceneRows =
    std::tuple<std::string,
               std::vector<std::tuple<std::string, std::vector<std::string>, std::string>>,
               std::vector<std::string>>;
SceneRows readScene(const std::string& path);
/// Writes a scene file: "volume", and every option of `command`'s sets at the keywords' values
/// (checked as the flags are) or its default; `tfJson`: an inline transfer function.
void writeScene(const std::string& path, const std::string& command, const std::string& volume,
                const Keywords& keywords, const std::string& tfJson);

/// The project's JSON text of a transfer function (py_transfer.cpp).
std::string transferJson(const TransferFunction& tf);

// ---- module parts --------------------------------------------------------------------

/// The Python Volume: the library's volume, shared with every Scene built from it.
struct PyVolume {
    std::shared_ptr<const Volume> volume;
};

/// A Scene shared with the Python object, and the cancellation its own settings' progress
/// reads (sequences and analyses render through Scene::settings()).
struct PyScene {
    std::shared_ptr<Scene> scene;
    std::shared_ptr<SceneCancel> cancel;
};
/// A Scene whose settings' progress reads `cancel` (settings.progress is replaced).
PyScene makeSceneFrom(std::shared_ptr<const Volume> volume, RenderSettings settings);

void bindVolume(py::module_& m);
void bindTransfer(py::module_& m);
void bindRender(py::module_& m);
void bindImage(py::module_& m);
void bindAnalysis(py::module_& m);
void bindGaussians(py::module_& m);  // py_gaussians.cpp

/// An H x W x 4 float32 array (premultiplied RGBA, row 0 on top) owning a copy of `image`'s
/// pixels... moved: no copy.
py::array_t<float> toArray(Image&& image);
/// A splat::Image from an H x W x 4 (or H x W x 3: alpha 1) float array.
Image fromArray(const py::array& a, const char* what);
/// Render statistics as a dict.
py::dict statsDict(const RenderStats& s);

}  // namespace splat::python
