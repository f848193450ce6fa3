// Analyses (splat/popping.h, splat/study.h) and surfaces (splat/surface.h): result objects
// whose series are NumPy arrays and whose events are plain Python data; write_report writes
// the CLI's report. Sweeps run with the GIL released and stop on Ctrl-C between tiles.
#include <cstring>

#include "py_common.h"
#include "splat/popping.h"
#include "splat/study.h"
#include "splat/surface.h"

namespace splat::python {

namespace {

py::array_t<double> doubles(const std::vector<double>& v) {
    py::array_t<double> a(py::ssize_t(v.size()));
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}

py::array_t<int> ints(const std::vector<int>& v) {
    py::array_t<int> a(py::ssize_t(v.size()));
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}

py::dict seriesDict(const RendererSeries& s) {
    py::dict d;
    d["T"] = doubles(s.T);
    d["J"] = doubles(s.J);
    d["flip_T"] = doubles(s.flipT);
    d["e"] = doubles(s.e);
    d["flip_ref"] = doubles(s.flipRef);
    // StopThePop's temporal FLIP (splat/warp.h): per pair, -1 where no pixel is valid; the
    // means None when not measured.
    d["flip_warp_1"] = doubles(s.flipWarp1);
    d["flip_warp_7"] = doubles(s.flipWarp7);
    d["flip_warp_1_mean"] =
        s.flipWarp1Mean >= 0 ? py::object(py::float_(s.flipWarp1Mean)) : py::none();
    d["flip_warp_7_mean"] =
        s.flipWarp7Mean >= 0 ? py::object(py::float_(s.flipWarp7Mean)) : py::none();
    d["sheet_axis"] = ints(s.sheetAxis);
    d["sheet_sign"] = ints(s.sheetSign);
    d["signal"] = doubles(s.signal);
    d["threshold"] = s.threshold;
    d["median_signal"] = s.medianSignal;
    d["spike_ratio"] = s.spikeRatio;
    d["median_T"] = s.medianT;
    d["flicker_ratio"] = s.flickerRatio;
    d["ms_per_frame"] = s.msPerFrame;
    d["total_ms"] = s.totalMs;
    return d;
}

/// The series' name (PoppingOptions::names, else the kind's).
std::string nameOf(const RendererSeries& s) {
    return s.name.empty() ? std::string(toString(s.renderer)) : s.name;
}

py::dict eventDict(const PoppingResult& r, const PoppingEvent& e) {
    py::dict d;
    d["renderer"] =
        e.series < r.series.size() ? nameOf(r.series[e.series]) : std::string(toString(e.renderer));
    d["angle_from"] = e.angleFrom;
    d["angle_to"] = e.angleTo;
    d["signal"] = e.signal;
    d["refined_jump"] = e.refinedJump;
    d["refined_width"] = e.refinedWidth;
    d["refined_slope"] = e.refinedSlope;
    d["refined_angle"] = e.refinedAngle;
    d["sheet_axis_before"] = e.sheetAxisBefore;
    d["sheet_axis_after"] = e.sheetAxisAfter;
    d["sheet_sign_before"] = e.sheetSignBefore;
    d["sheet_sign_after"] = e.sheetSignAfter;
    d["predicted"] = e.predicted;
    py::list steps;
    for (const RefinementStep& s : e.refinement) {
        py::dict st;
        st["width"] = s.width;
        st["from"] = s.from;
        st["change"] = s.change;
        st["jump"] = s.jump;
        steps.append(st);
    }
    d["refinement"] = steps;
    return d;
}

template <class F>
void writeReport(const std::string& folder, F&& write) {
    py::gil_scoped_release release;
    try {
        write();
    } catch (const Error& e) {
        rethrowFileError(e, folder, false);
    }
}

py::dict pointDict(const StudyPoint& p) {
    py::dict d;
    py::dict knobs;
    for (const auto& [k, v] : p.knobs) knobs[py::str(k)] = v;
    d["label"] = p.label();
    d["knobs"] = knobs;
    d["ms_median"] = p.msMedian;
    d["ms_min"] = p.msMin;
    d["ms_max"] = p.msMax;
    d["ms_mad"] = p.msMad;
    d["peak_mib"] = p.peakMiB;
    d["splats"] = p.splats;
    d["footprint_pixels"] = p.footprintPixels;
    d["footprint_pixel_rate"] = p.footprintPixelRate;
    d["rmse"] = p.rmse;
    d["psnr"] = p.psnr;
    d["max_abs"] = p.maxAbs;
    d["flip"] = p.flip;
    d["pareto"] = p.pareto;
    d["truth_filter"] = p.truthFilter;  // the reference's pixel filter (0: point-sampled)
    return d;
}

/// splat.popping and PoppingResult.
void bindPopping(py::module_& m) {
    py::class_<PoppingResult>(m, "PoppingResult",
                              "The result of splat.popping: per-renderer series (NumPy arrays) "
                              "and events (dicts); write_report(folder) writes the CLI's report.")
        .def_property_readonly(
            "angles", [](const PoppingResult& r) { return doubles(r.angles); },
            "The sweep's view angles, degrees.")
        .def_property_readonly(
            "renderers",
            [](const PoppingResult& r) {
                std::vector<std::string> out;
                for (const RendererSeries& s : r.series) out.push_back(nameOf(s));
                return out;
            },
            "Renderer names, in the order of the series.")
        .def_property_readonly(
            "series",
            [](const PoppingResult& r) {
                py::dict d;
                for (const RendererSeries& s : r.series) d[py::str(nameOf(s))] = seriesDict(s);
                return d;
            },
            "{renderer: {'T', 'J', 'flip_T' (per interval), 'e', 'flip_ref', 'sheet_axis', "
            "'sheet_sign' (per view), 'signal', and the numbers 'threshold', 'spike_ratio', "
            "'median_T', 'flicker_ratio', 'ms_per_frame', 'flip_warp_1', 'flip_warp_7' "
            "(StopThePop's temporal FLIP per frame pair) and their means "
            "'flip_warp_1_mean', 'flip_warp_7_mean' (None when not measured), ...}}")
        .def_property_readonly(
            "cross_jump", [](const PoppingResult& r) { return doubles(r.crossJump); },
            "C per interval (axis and sheet both present).")
        .def_property_readonly(
            "predicted_switches",
            [](const PoppingResult& r) { return doubles(r.predictedSwitches); },
            "Angles where the axis-aligned splatter's sheet axis changes (a Gaussian scene: "
            "where two overlapping Gaussians' centre depths swap; predicted_name says which).")
        .def_property_readonly(
            "predicted_name", [](const PoppingResult& r) { return r.options.predictedName; },
            "What predicted_switches are: 'sheet switch' or 'order swap'.")
        .def_property_readonly(
            "events",
            [](const PoppingResult& r) {
                py::list out;
                for (const PoppingEvent& e : r.events) out.append(eventDict(r, e));
                return out;
            },
            "The events, as dicts (summary.json's fields, and 'refinement').")
        .def_readonly("truth_filter", &PoppingResult::truthFilter,
                      "The reference's pixel filter sigma, pixels (0: the point-sampled "
                      "reference; truth=).")
        .def_readonly("total_ms", &PoppingResult::totalMs)
        .def(
            "write_report",
            [](const PoppingResult& r, const std::string& folder, const std::string& command) {
                writeReport(folder, [&] { writePoppingReport(r, folder, command); });
            },
            py::arg("folder"), py::arg("command_line") = "splat.popping (Python)",
            "Writes report.html, metrics.csv and summary.json into `folder` (which must exist), "
            "atomically, as `splat popping --report` does.");

    m.def(
        "_popping",
        [](const PyVolume& v, const Keywords& options, const std::string& tfJson,
           const py::object& progress) {
            OptionValues sweepValues(kSweepOptions);
            Sweep sweep;
            PoppingOptions o;
            RenderSettings settings = parseRenderSettings(
                options, tfJson, v.volume.get(), false, kSweepOptions,
                [&](const OptionValues& values, const RenderSettings& s) {
                    sweepValues = values;
                    poppingFrom(values, s, sweep, o);
                });
            settings.renderer = o.renderers.front();
            Sweep views = sweep;
            views.base = settings.camera;
            settings = poppingSettings(settings, *v.volume, poppingViews(sweepValues, views), o.truth);
            PyScene scene = makeSceneFrom(v.volume, settings);
            Interrupt in(progress);
            o.progress = in.progress();
            return interruptible(
                in,
                [&] {
                    const std::string& path = sweepValues.text("path");
                    if (path.empty()) return analyzePopping(*scene.scene, sweep, o);
                    return analyzePopping(
                        *scene.scene,
                        CameraPath::fromJson(path, scene.scene->settings().camera,
                                             int(sweepValues.integer("frames"))),
                        o);
                },
                scene.cancel.get());
        },
        py::arg("volume"), py::arg("options"), py::arg("tf_json"), py::arg("progress"));
    m.def("_popping_options", [] {
        std::vector<std::pair<std::string, std::string>> out;
        for (const auto& [keyword, flag, help, def] : poppingOptionTable())
            out.emplace_back(flag.substr(2), help);
        return out;
    });
}

/// splat.study, StudyResult and the study knobs.
void bindStudy(py::module_& m) {
    py::class_<StudyResult>(m, "StudyResult",
                            "The result of splat.study: one dict per setting (time, memory, "
                            "error, Pareto flag), convergence orders; write_report(folder).")
        .def_property_readonly(
            "points",
            [](const StudyResult& r) {
                py::list out;
                for (const StudyPoint& p : r.points) out.append(pointDict(p));
                return out;
            },
            "One dict per setting.")
        .def_property_readonly(
            "convergence",
            [](const StudyResult& r) {
                py::list out;
                for (const ConvergenceSeries& c : r.convergence) {
                    py::dict d;
                    d["parameter"] = c.parameter;
                    d["renderer"] = toString(c.renderer);
                    d["h"] = doubles(c.h);
                    d["error"] = doubles(c.error);
                    d["order"] = c.order;
                    out.append(d);
                }
                return out;
            },
            "Observed convergence orders (with convergence=True).")
        .def_readonly("visible_voxels", &StudyResult::visibleVoxels)
        .def_readonly("total_ms", &StudyResult::totalMs)
        .def(
            "write_report",
            [](const StudyResult& r, const std::string& folder, const std::string& command) {
                writeReport(folder, [&] { writeStudyReport(r, folder, command); });
            },
            py::arg("folder"), py::arg("command_line") = "splat.study (Python)",
            "Writes study.csv, study.json, pareto.svg and pareto.png into `folder`.");

    m.def(
        "_study",
        [](const PyVolume& v, const Keywords& options, const std::string& tfJson,
           const std::vector<std::string>& sweeps,
           const std::vector<std::pair<double, double>>& views, int repeats, int warmup,
           double truthStep, double truthTolerance, double ppd, bool convergence,
           const std::string& cacheDir, const std::string& truth, const py::object& progress) {
            RenderSettings settings = parseRenderSettings(options, tfJson, v.volume.get(), false);
            StudyOptions o;
            for (const std::string& s : sweeps) o.sweeps.push_back(parseKnob(s));
            for (const auto& [az, el] : views) o.views.emplace_back(az, el);
            if (repeats < 1 || repeats > 1000 || warmup < 0 || warmup > 1000)
                throw Error("--repeats must be 1..1000, --warmup 0..1000");
            if (!std::isfinite(truthStep) || !(truthStep >= 1e-3) || truthStep > 64 ||
                !std::isfinite(truthTolerance) || !(truthTolerance > 0) || !std::isfinite(ppd) ||
                !(ppd > 0))
                throw Error(
                    "--truth-step must be in [0.001, 64], --truth-tolerance and --ppd finite and "
                    "> 0");
            o.repeats = repeats;
            o.warmup = warmup;
            o.referenceStep = truthStep;
            o.referenceTolerance = truthTolerance;
            o.pixelsPerDegree = ppd;
            o.cacheDir = cacheDir;
            o.truth = parseTruth(truth);
            Interrupt in(progress);
            o.progress = in.progress();
            settings.progress = in.progress();
            return interruptible(in, [&] {
                StudyResult r = runStudy(v.volume, settings, o);
                if (convergence) {
                    ConvergenceOptions co;
                    co.progress = o.progress;
                    r.convergence = studyConvergence(v.volume, settings, co);
                }
                return r;
            });
        },
        py::arg("volume"), py::arg("options"), py::arg("tf_json"), py::arg("sweeps"), py::arg("views"),
        py::arg("repeats"), py::arg("warmup"), py::arg("truth_step"), py::arg("truth_tolerance"),
        py::arg("ppd"), py::arg("convergence"), py::arg("cache_dir"), py::arg("truth"),
        py::arg("progress"));
    m.def("study_knobs", &studyKnobNames, "Knob names splat.study sweeps.");
}

/// Mesh and splat.iso_surface.
void bindMesh(py::module_& m) {
    py::class_<Mesh>(m, "Mesh", "A triangle mesh in world coordinates (splat.iso_surface).")
        .def_property_readonly(
            "vertices",
            [](const Mesh& mesh) {
                py::array_t<float> a({py::ssize_t(mesh.vertices.size()), py::ssize_t(3)});
                std::memcpy(a.mutable_data(), mesh.vertices.data(), mesh.vertices.size() * 12);
                return a;
            },
            "V x 3 float32 world positions.")
        .def_property_readonly(
            "normals",
            [](const Mesh& mesh) {
                py::array_t<float> a({py::ssize_t(mesh.normals.size()), py::ssize_t(3)});
                std::memcpy(a.mutable_data(), mesh.normals.data(), mesh.normals.size() * 12);
                return a;
            },
            "V x 3 unit normals (outward: towards decreasing f).")
        .def_property_readonly(
            "triangles",
            [](const Mesh& mesh) {
                py::array_t<std::uint32_t> a({py::ssize_t(mesh.triangles.size()), py::ssize_t(3)});
                std::memcpy(a.mutable_data(), mesh.triangles.data(), mesh.triangles.size() * 12);
                return a;
            },
            "T x 3 vertex indices, counter-clockwise seen from outside.")
        .def_readonly("max_residual", &Mesh::maxResidual)
        .def(
            "write",
            [](const Mesh& mesh, const std::string& path) {
                writeReport(path, [&] { writeMesh(path, mesh); });
            },
            py::arg("path"), "Writes .ply, .obj or .stl atomically.");
    m.def(
        "iso_surface",
        [](const PyVolume& v, double level, const std::string& kernel, double sigma, double radius,
           int threads) {
            SurfaceOptions o;
            o.kernel = kernel;
            o.kernelSigma = sigma;
            o.kernelRadius = radius;
            o.threads = threads;
            Interrupt in;
            return interruptible(in, [&] { return extractIsosurface(*v.volume, level, o); });
        },
        py::arg("volume"), py::arg("level"), py::kw_only(), py::arg("kernel") = "gaussian",
        py::arg("sigma") = 0.0, py::arg("radius") = 0.0, py::arg("threads") = 0,
        "The iso surface f = level of the reconstructed field (as `splat iso`), a Mesh.");
}

}  // namespace

void bindAnalysis(py::module_& m) {
    bindPopping(m);
    bindStudy(m);
    bindMesh(m);
}

}  // namespace splat::python
