// The Python module splat._splat (docs/python.md; the package splat/__init__.py re-exports
// it): exception types, the long-call runner and the module's parts, one file per public
// type as in OpenImageIO's bindings.
#include <filesystem>

#include "py_common.h"
#include "splat/version.h"

namespace splat::python {

namespace {
PyObject* errorType = nullptr;       // splat.Error
PyObject* inputErrorType = nullptr;  // splat.InputError (ValueError)
PyObject* fileErrorType = nullptr;   // splat.FileError (OSError)
PyObject* cancelledType = nullptr;   // splat.Cancelled
}  // namespace

void rethrowFileError(const Error& e, const std::string& path, bool reading) {
    const std::string m = e.what();
    std::error_code ec;
    const bool missing =
        reading && path.rfind("synthetic:", 0) != 0 && !std::filesystem::exists(path, ec);
    bool osError = missing;
    for (const char* s : {"cannot open", "cannot read", "cannot write", "cannot create",
                          "No such file", "Permission denied", "Is a directory", "not a folder",
                          "does not exist", "Read-only file system", "No space left"})
        osError = osError || m.find(s) != std::string::npos;
    if (osError) throw FileFailure(m);
    throw e;
}

Interrupt::Interrupt(py::object progress) {
    if (!progress.is_none()) {
        if (!PyCallable_Check(progress.ptr()))
            throw Error("progress must be a callable progress(done, total, what)");
        callback = progress.ptr();
    }
}

ProgressFn Interrupt::progress() {
    return [this](std::size_t done, std::size_t total, const std::string& what) {
        if (stop) return false;
        if (callback) {
            py::gil_scoped_acquire gil;
            try {
                py::object r = py::reinterpret_borrow<py::object>(callback)(done, total, what);
                if (!r.is_none() && !r.cast<bool>()) {
                    byCallback = true;
                    stop = true;
                }
            } catch (...) {
                callbackError = std::current_exception();
                stop = true;
            }
        }
        return !stop.load();
    };
}

void runInterruptible(Interrupt& in, const std::function<void()>& work, SceneCancel* scene) {
    std::exception_ptr failure;
    {
        std::mutex mutex;
        std::condition_variable cv;
        bool done = false;
        py::gil_scoped_release release;
        std::thread worker([&] {
            try {
                work();
            } catch (...) {
                failure = std::current_exception();
            }
            std::lock_guard<std::mutex> lock(mutex);
            done = true;
            cv.notify_all();
        });
        std::unique_lock<std::mutex> lock(mutex);
        bool signalled = false;
        while (!cv.wait_for(lock, std::chrono::milliseconds(20), [&] { return done; })) {
            if (signalled) continue;
            lock.unlock();
            {
                py::gil_scoped_acquire gil;
                if (PyErr_CheckSignals() != 0) {
                    in.signalError = std::make_exception_ptr(py::error_already_set());
                    in.stop = true;
                    if (scene) ++scene->stop;
                    signalled = true;
                }
            }
            lock.lock();
        }
        lock.unlock();
        worker.join();
        if (signalled && scene) --scene->stop;
    }
    if (in.signalError) std::rethrow_exception(in.signalError);
    if (in.callbackError) std::rethrow_exception(in.callbackError);
    if (failure) std::rethrow_exception(failure);
}

}  // namespace splat::python

using namespace splat::python;

PYBIND11_MODULE(_splat, m) {
    m.doc() =
        "splat: splatting volume renderer (C++ core). Use the package `splat`, which "
        "re-exports this module with keyword arguments named after the command line's options.";
    m.attr("__version__") = splat::kVersion;

    py::object base = py::reinterpret_borrow<py::object>(PyExc_Exception);
    errorType = PyErr_NewExceptionWithDoc(
        "splat.Error",
        "Every error of the splat library: one line saying what, where and why (the command "
        "line prints the same line as `splat: error: ...`).",
        base.ptr(), nullptr);
    py::tuple inputBases = py::make_tuple(py::handle(errorType), py::handle(PyExc_ValueError));
    inputErrorType = PyErr_NewExceptionWithDoc(
        "splat.InputError", "A bad argument, option, array or file contents (also a ValueError).",
        inputBases.ptr(), nullptr);
    py::tuple fileBases = py::make_tuple(py::handle(errorType), py::handle(PyExc_OSError));
    fileErrorType = PyErr_NewExceptionWithDoc(
        "splat.FileError", "A file that cannot be found, read or written (also an OSError).",
        fileBases.ptr(), nullptr);
    cancelledType = PyErr_NewExceptionWithDoc(
        "splat.Cancelled", "A progress callable returned False: the call stopped cleanly.",
        errorType, nullptr);
    m.attr("Error") = py::handle(errorType);
    m.attr("InputError") = py::handle(inputErrorType);
    m.attr("FileError") = py::handle(fileErrorType);
    m.attr("Cancelled") = py::handle(cancelledType);

    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const FileFailure& e) {
            PyErr_SetString(fileErrorType, e.what());
        } catch (const splat::Cancelled& e) {
            PyErr_SetString(cancelledType, "cancelled: the progress callable returned False");
        } catch (const splat::Error& e) {
            PyErr_SetString(inputErrorType, e.what());
        }
    });

    bindVolume(m);
    bindTransfer(m);
    bindRender(m);
    bindImage(m);
    bindAnalysis(m);
    bindGaussians(m);
}
