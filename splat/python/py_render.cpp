// splat.render and splat.Scene (splat/render.h, splat/scene.h, splat/sequence.h): every
// frame is rendered with the GIL released and can be interrupted (Ctrl-C, progress=).
#include "py_common.h"
#include "splat/render.h"
#include "splat/sequence.h"
#include "splat/sparse_files.h"

namespace splat::python {

py::array_t<float> toArray(Image&& image) {
    auto* pixels = new std::vector<glm::vec4>(std::move(image.pixels));
    py::capsule owner(pixels, [](void* p) { delete static_cast<std::vector<glm::vec4>*>(p); });
    return py::array_t<float>({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(4)},
                              reinterpret_cast<const float*>(pixels->data()), owner);
}

py::dict statsDict(const RenderStats& s) {
    py::dict d;
    d["milliseconds"] = s.milliseconds;
    d["splats"] = s.splats;
    d["voxels"] = s.voxels;
    d["footprint_pixels"] = s.footprintPixels;
    d["sheets"] = s.sheets;
    d["culled_splats"] = s.culledSplats;
    d["reference_step"] = s.referenceStep;
    d["sheet_axis"] = s.sheetAxis;
    d["sheet_sign"] = s.sheetSign;
    d["slabs"] = s.slabs;
    d["shade_ms"] = s.shadeMs;
    d["project_ms"] = s.projectMs;
    d["order_ms"] = s.orderMs;
    d["bin_ms"] = s.binMs;
    d["tiles_ms"] = s.tilesMs;
    d["perspective"] = s.perspective;
    d["normals"] = s.normals;
    d["path_scale_pixels"] = s.pathScalePixels;
    d["exact_pixels"] = s.exactPixels;
    d["lod_level"] = s.lodLevel;
    d["lod_splats"] = s.lodSplats;
    return d;
}

namespace {

/// Frame progress that also stops when the Scene's cancellation is raised.
ProgressFn frameProgress(Interrupt& in, const std::shared_ptr<SceneCancel>& cancel) {
    ProgressFn p = in.progress();
    return [p, cancel](std::size_t d, std::size_t t, const std::string& w) {
        return p(d, t, w) && cancel->stop == 0;
    };
}

py::object renderResult(Image&& image, const RenderStats& stats, bool withStats) {
    py::array_t<float> a = toArray(std::move(image));
    if (!withStats) return a;
    return py::make_tuple(a, statsDict(stats));
}

PyScene makeScene(const PyVolume& v, const Keywords& options,
                  const std::string& tfJson) {
    return makeSceneFrom(v.volume, parseRenderSettings(options, tfJson, v.volume.get(), true));
}

}  // namespace

PyScene makeSceneFrom(std::shared_ptr<const Volume> volume, RenderSettings s) {
    PyScene out;
    out.cancel = std::make_shared<SceneCancel>();
    s.progress = [cancel = out.cancel](std::size_t, std::size_t, const std::string&) {
        return cancel->stop == 0;
    };
    Interrupt in;
    out.scene = interruptible(in, [&] { return std::make_shared<Scene>(volume, s); });
    return out;
}

void bindRender(py::module_& m) {
    m.def(
        "_render",
        [](const PyVolume& v, const Keywords& options, const std::string& tfJson,
           const py::object& progress, bool withStats) {
            RenderSettings s = parseRenderSettings(options, tfJson, v.volume.get(), true);
            Interrupt in(progress);
            s.progress = in.progress();
            RenderStats stats;
            Image image = interruptible(in, [&] {
                const Renderer renderer(v.volume, s);
                return renderer.render(&stats);
            });
            return renderResult(std::move(image), stats, withStats);
        },
        py::arg("volume"), py::arg("options"), py::arg("tf_json"), py::arg("progress"),
        py::arg("return_stats"));
    m.def("_render_options", &renderOptionTable);
    m.def("_read_scene", &readScene, py::arg("path"),
          "A scene file read by the library: (command, [(keyword, texts, object_json)], "
          "other_keys).");
    m.def("_write_scene", &writeScene, py::arg("path"), py::arg("command"), py::arg("volume"),
          py::arg("options"), py::arg("tf_json"), "Writes a scene file by the library.");
    m.def(
        "_zarr_level",
        [](const std::string& path, const Keywords& options, const std::string& tfJson) {
            const RenderSettings s = parseRenderSettings(options, tfJson, nullptr, true);
            return zarrLevelForView(describeZarr(path), s);
        },
        py::arg("path"), py::arg("options"), py::arg("tf_json"));
    m.def(
        "_option_specs",
        [] {
            // (name, type, default, set, is a path) per option of the table, for the tests.
            static const char* const types[] = {"flag", "integer", "unsigned",
                                                "real", "text",    "list"};
            std::vector<std::tuple<std::string, std::string, std::string, std::string, bool>> out;
            for (const OptionSpec* spec : optionsOf(kSharedOptions)) {
                const OptionSpec& o = *spec;
                const char* set = o.set == kVolumeOptions  ? "volume"
                                  : o.set == kRenderOptions ? "render"
                                  : o.set == kImageOptions  ? "image"
                                                            : "sweep";
                out.emplace_back(std::string(o.name), types[int(o.type)],
                                 std::string(o.defaultText), set, o.path != OptionPath::None);
            }
            return out;
        },
        "The option table (splat/options.h): (name, type, default, set, is_path) per option.");

    py::class_<PyScene>(m, "_Scene")
        .def(py::init(&makeScene), py::arg("volume"), py::arg("options"), py::arg("tf_json"))
        .def(
            "render",
            [](const PyScene& p, const Keywords& options, const std::string& tfJson,
               const py::object& progress, bool withStats, bool depth) {
                RenderSettings s = parseRenderSettings(options, tfJson, &p.scene->volume(), true);
                Interrupt in(progress);
                s.progress = frameProgress(in, p.cancel);
                RenderStats stats;
                Image image = interruptible(
                    in,
                    [&] {
                        return depth ? p.scene->renderIsoDepth(s, &stats)
                                     : p.scene->render(s, &stats);
                    },
                    p.cancel.get());
                return renderResult(std::move(image), stats, withStats);
            },
            py::arg("options"), py::arg("tf_json"), py::arg("progress"), py::arg("return_stats"),
            py::arg("depth"))
        .def(
            "sequence",
            [](const PyScene& p, const std::string& sweep, double from, double to, int frames,
               const std::string& pathFile, int parallelFrames, std::size_t first,
               std::size_t count, const py::object& progress) {
                if (frames < 1 || frames > 1000000)
                    throw Error("--frames must be between 1 and 1000000");
                if (sweep != "azimuth" && sweep != "elevation")
                    throw Error("--sweep must be azimuth or elevation");
                if (parallelFrames < 0) throw Error("--parallel-frames must be >= 0");
                const RenderSettings& base = p.scene->settings();
                const CameraPath path =
                    pathFile.empty()
                        ? CameraPath::turn(base.camera,
                                           sweep == "azimuth" ? CameraPath::Angle::Azimuth
                                                              : CameraPath::Angle::Elevation,
                                           from, to, frames)
                        : CameraPath::fromJson(pathFile, base.camera, frames);
                Interrupt in(progress);
                SequenceOptions o;
                o.parallelFrames = parallelFrames;
                o.progress = in.progress();
                o.skip = [first, count](std::size_t v) { return v < first || v >= first + count; };
                std::vector<Image> images;
                interruptible(
                    in,
                    [&] {
                        renderSequence(*p.scene, {base.renderer}, path, o, [&](SequenceFrame&& f) {
                            images.push_back(std::move(f.images.front()));
                        });
                    },
                    p.cancel.get());
                py::list out;
                for (Image& im : images) out.append(toArray(std::move(im)));
                return out;
            },
            py::arg("sweep"), py::arg("from_"), py::arg("to"), py::arg("frames"), py::arg("path"),
            py::arg("parallel_frames"), py::arg("first"), py::arg("count"), py::arg("progress"))
        .def_property_readonly("splat_count",
                               [](const PyScene& p) { return p.scene->splats().size(); })
        .def_property_readonly("splat_bytes",
                               [](const PyScene& p) { return p.scene->splats().bytes(); })
        .def_property_readonly("transfer",
                               [](const PyScene& p) { return p.scene->settings().transfer; });
}

}  // namespace splat::python
