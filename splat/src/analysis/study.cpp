// Speed-accuracy studies and convergence orders (see splat/study.h).
#include "splat/study.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "analysis/median.h"
#include "frame/stopwatch.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/frame_farm.h"
#include "splat/image_io.h"
#include "splat/metrics.h"
#include "splat/options.h"
#include "splat/render.h"
#include "splat/scene.h"

#if __has_include("splat/flip.h")
#include "splat/flip.h"
#define SPLAT_STUDY_HAVE_FLIP 1
#endif

namespace splat {

namespace {

using analysis::median;

/// Peak resident set size since the last reset (Linux /proc; 0 elsewhere), MiB.
void resetPeakMemory() {
    std::ofstream clear("/proc/self/clear_refs");
    if (clear) clear << "5";
}
double peakMemoryMiB() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
    return 0;
}

#if defined(SPLAT_STUDY_HAVE_FLIP)
/// Linear RGB in [0, 1] for LDR-FLIP: dvr as composited; mip/xray divided by `peak`.
Image displayValues(const Image& img, RenderMode mode, float peak) {
    Image out = img;
    const float scale =
        (mode == RenderMode::Dvr || mode == RenderMode::Iso || !(peak > 0)) ? 1.0f : 1.0f / peak;
    for (auto& p : out.pixels) {
        for (int c = 0; c < 3; ++c) {
            const float v = p[c] * scale;
            p[c] = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
        }
        p.a = 1.0f;
    }
    return out;
}
#endif

float peakOf(const Image& img) {
    float m = 0;
    for (const auto& p : img.pixels)
        for (int c = 0; c < 3; ++c)
            if (std::isfinite(p[c])) m = std::max(m, p[c]);
    return m;
}

std::string fmt(double v) {
    std::ostringstream o;
    o.precision(6);
    o << v;
    return o.str();
}

/// The settings that define the reference's model and view: key of the reference cache.
std::string referenceKey(const RenderSettings& s, const StudyOptions& o) {
    std::ostringstream k;
    k.precision(10);
    k << toString(s.mode) << '|' << toString(s.classification) << '|' << s.transfer.name << '|'
      << s.kernel << '|' << s.kernelSigma << '|' << s.kernelRadius << '|' << s.shading.enabled
      << '|' << s.camera.width << 'x' << s.camera.height << '|' << s.camera.azimuthDeg << '|'
      << s.camera.elevationDeg << '|' << toString(s.camera.projection) << '|' << s.camera.pixelSize
      << '|' << s.camera.fovDeg << '|' << s.camera.distance << '|' << o.referenceStep << '|'
      << o.referenceTolerance << '|' << s.background.r << ',' << s.background.g << ','
      << s.background.b << ',' << s.background.a;
    if (s.quality.pixelFilter > 0)
        k << "|pixel-filter " << s.quality.pixelFilter << ',' << s.quality.pixelFilterTolerance;
    return k.str();
}

/// A measured point as the journal keeps it (doubles round-trip exactly; NaN as null).
nlohmann::json pointJson(const StudyPoint& p) {
    auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
    return {{"label", p.label()},
            {"ms_median", p.msMedian},
            {"ms_min", p.msMin},
            {"ms_max", p.msMax},
            {"ms_mad", p.msMad},
            {"peak_mib", p.peakMiB},
            {"splats", p.splats},
            {"footprint_pixels", p.footprintPixels},
            {"footprint_pixel_rate", p.footprintPixelRate},
            {"rmse", num(p.rmse)},
            {"psnr", num(p.psnr)},
            {"max_abs", num(p.maxAbs)},
            {"flip", num(p.flip)},
            {"exact_frames", p.exactFrames},
            {"truth_filter", p.truthFilter}};
}

void restorePoint(StudyPoint& p, const nlohmann::json& j) {
    auto num = [&](const char* k) { return j.at(k).is_null() ? NAN : j.at(k).get<double>(); };
    p.msMedian = num("ms_median");
    p.msMin = num("ms_min");
    p.msMax = num("ms_max");
    p.msMad = num("ms_mad");
    p.peakMiB = num("peak_mib");
    p.splats = j.at("splats").get<std::size_t>();
    p.footprintPixels = j.at("footprint_pixels").get<std::size_t>();
    p.exactFrames = j.value("exact_frames", std::size_t(0));
    p.truthFilter = j.value("truth_filter", 0.0);
    p.footprintPixelRate = num("footprint_pixel_rate");
    p.rmse = num("rmse");
    p.psnr = num("psnr");
    p.maxAbs = num("max_abs");
    p.flip = num("flip");
}

class Progress {
  public:
    Progress(const ProgressFn& fn, std::size_t total) : fn_(fn), total_(total) {}
    void step(const std::string& what) {
        ++done_;
        if (fn_ && !fn_(done_, std::max(total_, done_), what)) throw Cancelled();
    }
    /// Inside a frame: the same done and total, so that a cancel stops the frame in flight.
    bool poll(const std::string& what) const { return !fn_ || fn_(done_, total_, what); }

  private:
    const ProgressFn& fn_;
    std::size_t total_, done_ = 0;
};

}  // namespace

std::vector<std::string> studyKnobNames() {
    return {studyKnobs().begin(), studyKnobs().end()};
}

bool isSceneKnob(const std::string& n) {
    const OptionSpec* o = findOption(n);
    return o && o->scope == OptionScope::Scene;
}

void applyKnob(RenderSettings& s, const std::string& n, const std::string& v) {
    const auto& knobs = studyKnobs();
    if (std::find(knobs.begin(), knobs.end(), n) == knobs.end()) {
        std::string all;
        for (const auto& k : knobs) all += (all.empty() ? "" : ", ") + std::string(k);
        throw Error("unknown study knob '" + n + "' (knobs: " + all + ")");
    }
    // A study's size may be one number N: N x N pixels.
    const bool square = n == "size" && v.find_first_of("xX") == std::string::npos;
    applyOption(s, n, square ? v + "x" + v : v);
}

StudyKnob parseKnob(const std::string& text) {
    const auto eq = text.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 >= text.size())
        throw Error("--sweep '" + text + "' must look like KNOB=V1,V2,...");
    StudyKnob k;
    k.name = text.substr(0, eq);
    std::stringstream in(text.substr(eq + 1));
    std::string item;
    while (std::getline(in, item, ','))
        if (!item.empty()) k.values.push_back(item);
    if (k.values.empty()) throw Error("--sweep '" + text + "' has no values");
    RenderSettings probe;
    for (const auto& v : k.values) applyKnob(probe, k.name, v);  // refuse bad values early
    return k;
}

std::string StudyPoint::label() const {
    std::string out;
    for (const auto& [k, v] : knobs) out += (out.empty() ? "" : " ") + k + "=" + v;
    return out.empty() ? "base" : out;
}

void markPareto(std::vector<StudyPoint>& points) {
    for (auto& p : points) {
        p.pareto = std::isfinite(p.rmse);
        for (const auto& q : points)
            if (&q != &p && q.msMedian <= p.msMedian && q.rmse <= p.rmse &&
                (q.msMedian < p.msMedian || q.rmse < p.rmse)) {
                p.pareto = false;
                break;
            }
    }
}

double fitOrder(const std::vector<double>& h, const std::vector<double>& e) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (std::size_t i = 0; i < h.size() && i < e.size(); ++i) {
        if (!(e[i] > 0) || !(h[i] > 0)) continue;
        const double x = std::log(h[i]), y = std::log(e[i]);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        ++n;
    }
    const double den = n * sxx - sx * sx;
    return n >= 2 && den > 0 ? (n * sxy - sx * sy) / den : 0.0;
}

Image boxDownsample(const Image& img, int f) {
    if (f <= 1) return img;
    Image out(img.width / f, img.height / f);
    const float inv = 1.0f / float(f * f);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            glm::vec4 sum(0.0f);
            for (int j = 0; j < f; ++j)
                for (int i = 0; i < f; ++i) sum += img.at(x * f + i, y * f + j);
            out.at(x, y) = sum * inv;
        }
    return out;
}

RenderSettings studyReferenceSettings(const RenderSettings& base, const StudyOptions& options,
                                      const CameraParams& camera, const Quality* frame) {
    RenderSettings r = base;
    r.renderer = RendererKind::Reference;
    r.camera = camera;
    r.quality.referenceStep = options.referenceStep;
    r.quality.referenceTolerance = options.referenceTolerance;
    if (frame) {  // the reference is filtered through the frame's pixel filter (a swept one too)
        r.quality.pixelFilter = frame->pixelFilter;
        r.quality.pixelFilterTolerance = frame->pixelFilterTolerance;
    }
    return r;
}

namespace {
/// The reference that judges `frame` (a point's frame at one view): the study's reference
/// settings, through the pixel filter options.truth asks for (truthFilter).
RenderSettings judgingReference(const RenderSettings& base, const StudyOptions& options,
                                const RenderSettings& frame, const Volume& volume) {
    RenderSettings r = studyReferenceSettings(base, options, frame.camera, &frame.quality);
    r.quality.pixelFilter = truthFilter(frame, volume, {frame.camera}, options.truth);
    return r;
}
}  // namespace

namespace {

/// One setting of a study: (knob, value) per swept knob.
using Combo = std::vector<std::pair<std::string, std::string>>;

// Slab knobs mean nothing to the axis-aligned splatter and the reference: their settings are
// measured once (first slab values) and listed without the slab knobs.
bool isSlabKnob(const std::string& k) {
    return k == "slab" || k == "slab-radial-res" || k == "slab-depth-res";
}

bool isSheet(const RenderSettings& base, const Combo& combo) {
    RenderSettings probe = base;
    for (const auto& [k, v] : combo)
        if (k == "renderer") applyKnob(probe, k, v);
    return probe.renderer == RendererKind::Sheet;
}

/// Every combination of the swept values, scene knobs outermost (so that each Scene is built
/// once), without the repeats of a slab knob where it means nothing.
std::vector<Combo> studyCombinations(const RenderSettings& base,
                                     const std::vector<StudyKnob>& sweeps) {
    std::vector<StudyKnob> knobs = sweeps;
    std::stable_partition(knobs.begin(), knobs.end(),
                          [](const StudyKnob& k) { return isSceneKnob(k.name); });
    std::vector<Combo> combos(1);
    for (const auto& k : knobs) {
        std::vector<Combo> next;
        for (const auto& c : combos)
            for (const auto& v : k.values) {
                auto d = c;
                d.emplace_back(k.name, v);
                next.push_back(std::move(d));
            }
        combos = std::move(next);
    }
    std::erase_if(combos, [&](const Combo& combo) {
        if (isSheet(base, combo)) return false;
        for (const auto& [k, v] : combo)
            if (isSlabKnob(k))
                for (const auto& sw : knobs)
                    if (sw.name == k && v != sw.values.front()) return true;
        return false;
    });
    return combos;
}

/// The quality presets as points of their own (StudyOptions::presets), after the sweep's.
void appendPresetCombinations(std::vector<Combo>& combos, const std::vector<StudyKnob>& sweeps) {
    for (const StudyKnob& k : sweeps)
        if (k.name == "quality") return;
    for (QualityPreset p : {QualityPreset::Fast, QualityPreset::Default, QualityPreset::Exact})
        combos.push_back({{"quality", toString(p)}});
}

/// The study's views: the base camera, or one per (azimuth, elevation) asked for.
std::vector<CameraParams> studyViews(const RenderSettings& base, const StudyOptions& options) {
    if (options.views.empty()) return {base.camera};
    std::vector<CameraParams> views;
    for (const glm::dvec2& v : options.views) {
        CameraParams c = base.camera;
        c.azimuthDeg = v.x;
        c.elevationDeg = v.y;
        views.push_back(c);
    }
    return views;
}

/// The references: the base model (its scene knobs), per view and image size, rendered once,
/// read from and written to the cache folder, or rendered ahead on a frame farm.
class StudyReferences {
  public:
    StudyReferences(std::shared_ptr<const Volume> volume, const RenderSettings& base,
                    const StudyOptions& options)
        : volume_(std::move(volume)), base_(base), options_(options) {}

    /// The reference `frame` is judged against.
    const Image& forFrame(const RenderSettings& frame) {
        const RenderSettings r = judgingReference(base_, options_, frame, *volume_);
        const std::string key = referenceKey(r, options_);
        if (auto it = references_.find(key); it != references_.end()) return it->second;
        if (auto it = prefetched_.find(key); it != prefetched_.end()) {
            Image& img = references_[key] = std::move(it->second);
            prefetched_.erase(it);
            return img;
        }
        if (std::optional<Image> img = cached(r)) return references_[key] = std::move(*img);
        Image img = render(r);
        writeCache(r, img);
        return references_[key] = std::move(img);
    }

    /// On a frame farm, every reference missing is rendered first, spread over its processes
    /// (the ground truth is the costly part); nothing is timed while they run.
    void renderOnFarm(FrameFarm& farm, const std::vector<Combo>& combos,
                      const std::vector<CameraParams>& views) {
        std::vector<RenderSettings> wanted;
        std::vector<FrameJob> jobs;
        for (const auto& combo : combos) {
            RenderSettings s = base_;
            for (const auto& [k, v] : combo) applyKnob(s, k, v);
            for (const CameraParams& view : views) {
                CameraParams c = view;
                c.width = s.camera.width;
                c.height = s.camera.height;
                s.camera = c;
                const RenderSettings r = judgingReference(base_, options_, s, *volume_);
                // The farm's Scenes render the base pixel filter; a swept one stays on rank 0.
                if (r.quality.pixelFilter != base_.quality.pixelFilter ||
                    r.quality.pixelFilterTolerance != base_.quality.pixelFilterTolerance)
                    continue;
                const std::string key = referenceKey(r, options_);
                if (prefetched_.count(key)) continue;
                if (std::optional<Image> img = cached(r)) {
                    prefetched_[key] = std::move(*img);
                    continue;
                }
                prefetched_[key] = Image();  // claimed: rendered by the farm below
                jobs.push_back({wanted.size(), r.camera});
                wanted.push_back(r);
            }
        }
        farm.render(
            {RendererKind::Reference}, jobs,
            [&](const FrameJob& job) {
                SequenceFrame f;
                f.view = job.view;
                f.images.push_back(render(wanted[job.view]));
                f.stats.resize(1);
                return f;
            },
            [&](SequenceFrame&& f) {
                const RenderSettings& r = wanted[f.view];
                writeCache(r, f.images[0]);
                prefetched_[referenceKey(r, options_)] = std::move(f.images[0]);
            });
    }

    /// The peak of the references asked for so far: the PSNR scale, as in one process.
    double peak() const {
        double p = 0;
        for (const auto& [k, img] : references_) p = std::max(p, double(peakOf(img)));
        return p;
    }

  private:
    std::string cacheFile(const std::string& key) const {
        if (options_.cacheDir.empty()) return {};
        return (std::filesystem::path(options_.cacheDir) /
                ("reference_" + std::to_string(std::hash<std::string>{}(key + volume_->source)) +
                 ".exr"))
            .string();
    }
    std::optional<Image> cached(const RenderSettings& r) const {
        const std::string file = cacheFile(referenceKey(r, options_));
        if (!file.empty() && std::filesystem::exists(file)) {
            // A cached reference that does not decode whole (damaged) is rendered again.
            try {
                Image img = readImage(file);
                if (img.width == r.camera.width && img.height == r.camera.height) return img;
            } catch (const Error&) {
            }
        }
        return std::nullopt;
    }
    void writeCache(const RenderSettings& r, const Image& img) const {
        const std::string file = cacheFile(referenceKey(r, options_));
        if (file.empty()) return;
        std::filesystem::create_directories(options_.cacheDir);
        WriteOptions wo;
        writeImage(file, img, wo);
    }
    Image render(const RenderSettings& r) {
        if (!scene_) scene_ = std::make_unique<Scene>(volume_, r);
        return scene_->render(r);
    }

    std::shared_ptr<const Volume> volume_;
    const RenderSettings& base_;
    const StudyOptions& options_;
    std::map<std::string, Image> references_;
    /// Rendered (or read) ahead on a frame farm, moved to references_ when a point first asks.
    std::map<std::string, Image> prefetched_;
    std::unique_ptr<Scene> scene_;
};

/// Points measured by an interrupted run (StudyOptions::pointJournal), by label.
std::map<std::string, nlohmann::json> readPointJournal(const StudyOptions& options) {
    std::map<std::string, nlohmann::json> journaled;
    if (options.pointJournal.empty() || !std::filesystem::exists(options.pointJournal))
        return journaled;
    try {
        std::ifstream in(options.pointJournal);
        for (const auto& p : nlohmann::json::parse(in)) journaled[p.at("label")] = p;
    } catch (const std::exception&) {
        journaled.clear();  // unreadable: measured again
    }
    return journaled;
}

/// Adds a measured point to the journal and writes it whole.
void journalPoint(const StudyOptions& options, std::map<std::string, nlohmann::json>& journaled,
                  const StudyPoint& point, std::size_t visible) {
    if (options.pointJournal.empty()) return;
    nlohmann::json j = pointJson(point);
    j["visible"] = visible;
    journaled[point.label()] = j;
    nlohmann::json all = nlohmann::json::array();
    for (const auto& [label, p] : journaled) all.push_back(p);
    writeTextAtomic(options.pointJournal, all.dump() + "\n");
}

/// The point of a combination: its knobs (without slab knobs where they mean nothing) in the
/// order of the sweeps as given, for the label.
StudyPoint pointOf(const RenderSettings& base, const Combo& combo, const StudyOptions& options) {
    StudyPoint point;
    point.knobs = combo;
    if (!isSheet(base, combo))
        std::erase_if(point.knobs, [&](const auto& kv) { return isSlabKnob(kv.first); });
    std::stable_sort(point.knobs.begin(), point.knobs.end(), [&](const auto& a, const auto& b) {
        auto pos = [&](const std::string& n) {
            for (std::size_t i = 0; i < options.sweeps.size(); ++i)
                if (options.sweeps[i].name == n) return i;
            return options.sweeps.size();
        };
        return pos(a.first) < pos(b.first);
    });
    return point;
}

/// A frame of the Scene with the per-frame knobs of `s`.
RenderSettings frameOf(const Scene& scene, const RenderSettings& s) {
    RenderSettings frame = scene.settings();
    frame.renderer = s.renderer;
    frame.order = s.order;
    frame.camera = s.camera;
    frame.background = s.background;
    frame.threads = s.threads;
    frame.quality.slab = s.quality.slab;
    frame.quality.earlyTermination = s.quality.earlyTermination;
    frame.quality.factorisedSheets = s.quality.factorisedSheets;
    frame.quality.warpTolerance = s.quality.warpTolerance;
    frame.quality.referenceStep = s.quality.referenceStep;
    frame.quality.referenceTolerance = s.quality.referenceTolerance;
    frame.quality.tileSize = s.quality.tileSize;
    frame.quality.lod = s.quality.lod;
    frame.quality.ewa = s.quality.ewa;
    frame.quality.pixelFilter = s.quality.pixelFilter;
    frame.quality.pixelFilterTolerance = s.quality.pixelFilterTolerance;
    return frame;
}

/// `frame` at view `view` with the image size of `s`.
RenderSettings atView(RenderSettings frame, const CameraParams& view, const RenderSettings& s) {
    frame.camera = view;
    frame.camera.width = s.camera.width;
    frame.camera.height = s.camera.height;
    return frame;
}

/// What a study measures a point with.
struct StudyRun {
    std::shared_ptr<const Volume> volume;
    const RenderSettings& base;
    const StudyOptions& options;
    const std::vector<CameraParams>& views;
    StudyReferences& references;
    Progress& progress;
};

/// Renders the point's views (warm-up, then the timed repeats) and compares each with its
/// reference: times, memory, splat counts and errors. Returns the most splats of a frame.
std::size_t measurePoint(const StudyRun& run, const Scene& scene, const RenderSettings& s,
                         StudyPoint& point) {
    const StudyOptions& options = run.options;
    std::size_t visible = 0;
    std::vector<double> ms;
    double sumSq = 0, sumMax = 0, sumFlip = 0;
    for (std::size_t v = 0; v < run.views.size(); ++v) {
        RenderSettings frame = atView(point.settings, run.views[v], s);
        Image img;
        RenderStats st;
        for (int r = 0; r < options.warmup + options.repeats; ++r) {
            frame.progress = [&](std::size_t, std::size_t, const std::string& what) {
                return run.progress.poll(point.label() + ": " + what);
            };
            img = scene.render(frame, &st);
            frame.progress = nullptr;
            if (r >= options.warmup) ms.push_back(st.milliseconds);
            if (r >= options.warmup && st.exactPixels > 0) ++point.exactFrames;
            run.progress.step(point.label());
        }
        if (v == 0) {
            point.splats = st.splats;
            point.footprintPixels = st.footprintPixels;
        }
        visible = std::max(visible, st.splats);
        point.peakMiB = std::max(point.peakMiB, peakMemoryMiB());
        const Image& ref = run.references.forFrame(frame);
        point.truthFilter =
            std::max(point.truthFilter,
                     judgingReference(run.base, options, frame, *run.volume).quality.pixelFilter);
        const ImageMetrics m = compareImages(img, ref);
        sumSq += m.rmse * m.rmse;
        sumMax = std::max(sumMax, m.maxAbs);
#if defined(SPLAT_STUDY_HAVE_FLIP)
        const float peak = peakOf(ref);
        FlipOptions fo;
        fo.pixelsPerDegree = options.pixelsPerDegree;
        sumFlip += flipMean(displayValues(img, frame.mode, peak),
                            displayValues(ref, frame.mode, peak), fo);
#else
        (void)sumFlip;
#endif
    }
    const double views = double(run.views.size());
    point.rmse = std::sqrt(sumSq / views);
    point.maxAbs = sumMax;
    point.psnr = 20.0 * std::log10(std::max(run.references.peak(), 1e-12) /
                                   std::max(point.rmse, 1e-300));
#if defined(SPLAT_STUDY_HAVE_FLIP)
    point.flip = sumFlip / views;
#endif
    point.msMedian = median(ms);
    point.msMin = *std::min_element(ms.begin(), ms.end());
    point.msMax = *std::max_element(ms.begin(), ms.end());
    std::vector<double> dev;
    for (double t : ms) dev.push_back(std::abs(t - point.msMedian));
    point.msMad = median(dev);
    point.footprintPixelRate =
        point.msMedian > 0 ? double(point.footprintPixels) / (point.msMedian / 1000.0) : 0;
    return visible;
}

/// A point measured by an interrupted run: its figures are kept, and its references loaded as
/// that run did (the PSNR scale is the peak of those seen so far).
void restoreJournaled(const StudyRun& run, const RenderSettings& s, StudyPoint& point,
                      const nlohmann::json& saved) {
    for (const CameraParams& view : run.views) {
        (void)run.references.forFrame(atView(point.settings, view, s));
        for (int r = 0; r < run.options.warmup + run.options.repeats; ++r)
            run.progress.step(point.label());
    }
    restorePoint(point, saved);
}

}  // namespace

StudyResult runStudy(std::shared_ptr<const Volume> volume, const RenderSettings& base,
                     const StudyOptions& options) {
    const auto start = Clock::now();
    if (options.repeats < 1 || options.warmup < 0)
        throw Error("study: repeats must be >= 1 and warm-up >= 0");
    StudyResult result;
    result.base = base;
    result.options = options;
    result.options.progress = nullptr;
    result.volume = volume->source;
#if defined(SPLAT_STUDY_HAVE_FLIP)
    result.flipAvailable = true;
#endif
    for (const auto& k : options.sweeps) (void)parseKnob(k.name + "=" + k.values.front());
    std::vector<Combo> combos = studyCombinations(base, options.sweeps);
    if (options.presets) appendPresetCombinations(combos, options.sweeps);
    const std::vector<CameraParams> views = studyViews(base, options);
    Progress progress(options.progress,
                      combos.size() * views.size() * std::size_t(options.repeats + options.warmup));
    StudyReferences references(volume, base, options);
    if (FrameFarm* farm = installedFrameFarm()) references.renderOnFarm(*farm, combos, views);
    std::map<std::string, nlohmann::json> journaled = readPointJournal(options);
    const StudyRun run{volume, base, options, views, references, progress};

    std::unique_ptr<Scene> scene;
    std::string sceneKey = "?";
    for (const Combo& combo : combos) {
        RenderSettings s = base;
        std::string key;
        for (const auto& [k, v] : combo) {
            applyKnob(s, k, v);
            if (isSceneKnob(k)) key += k + "=" + v + ";";
        }
        StudyPoint point = pointOf(base, combo, options);
        resetPeakMemory();
        if (key != sceneKey || !scene) {
            scene.reset();
            // The Scene is validated against its first renderer (iso: the reference).
            scene = std::make_unique<Scene>(volume, s);
            sceneKey = key;
        }
        point.settings = frameOf(*scene, s);
        if (auto done = journaled.find(point.label()); done != journaled.end()) {
            restoreJournaled(run, s, point, done->second);
            result.visibleVoxels =
                std::max(result.visibleVoxels, done->second.value("visible", std::size_t(0)));
            result.points.push_back(std::move(point));
            continue;
        }
        const std::size_t visible = measurePoint(run, *scene, s, point);
        result.visibleVoxels = std::max(result.visibleVoxels, visible);
        journalPoint(options, journaled, point, visible);
        result.points.push_back(std::move(point));
    }
    markPareto(result.points);
    result.totalMs = msSince(start);
    return result;
}

std::vector<ConvergenceSeries> studyConvergence(std::shared_ptr<const Volume> volume,
                                                const RenderSettings& base,
                                                const ConvergenceOptions& o) {
    std::vector<ConvergenceSeries> out;
    const std::size_t total =
        o.slabs.size() + 1 + o.referenceSteps.size() + 3 * o.sizes.size() + o.sizes.size();
    Progress progress(o.progress, total);
    RenderSettings ref = base;
    ref.renderer = RendererKind::Reference;
    const Scene scene(volume, ref);
    RenderSettings frame = scene.settings();

    // Slab: the image-aligned splatter against a fine reference.
    frame.renderer = RendererKind::Reference;
    frame.quality.referenceStep = 0.0625;
    frame.quality.referenceTolerance = 1e-6;
    const Image fine = scene.render(frame);
    progress.step("reference");
    if (base.mode == RenderMode::Dvr || base.mode == RenderMode::Mip) {
        ConvergenceSeries slab{"slab", RendererKind::Sheet, {}, {}, 0};
        RenderSettings f = scene.settings();
        f.renderer = RendererKind::Sheet;
        f.quality.earlyTermination = 0;
        for (double t : o.slabs) {
            f.quality.slab = t;
            slab.h.push_back(t);
            slab.error.push_back(compareImages(scene.render(f), fine).rmse);
            progress.step("slab " + fmt(t));
        }
        slab.order = fitOrder(slab.h, slab.error);
        out.push_back(slab);
    }
    // Reference step: a fixed step (no refinement: the tolerance is never met) against
    // the next finer one (Richardson-style differences).
    {
        ConvergenceSeries rs{"reference-step", RendererKind::Reference, {}, {}, 0};
        std::vector<Image> imgs;
        RenderSettings f = scene.settings();
        f.renderer = RendererKind::Reference;
        f.quality.referenceTolerance = 1e30;
        for (double h : o.referenceSteps) {
            f.quality.referenceStep = h;
            imgs.push_back(scene.render(f));
            progress.step("reference step " + fmt(h));
        }
        for (std::size_t i = 0; i + 1 < imgs.size(); ++i) {
            rs.h.push_back(o.referenceSteps[i]);
            rs.error.push_back(compareImages(imgs[i], imgs[i + 1]).rmse);
        }
        rs.order = fitOrder(rs.h, rs.error);
        out.push_back(rs);
    }
    // Pixel size: each renderer at N pixels against the reference box-filtered from 4N.
    {
        const double side = std::min(base.camera.width, base.camera.height);
        const Camera probe(base.camera, *volume);
        const double extent = probe.pixelSize * side;  // world size of the image's short side
        std::vector<Image> truths;
        for (int n : o.sizes) {
            RenderSettings f = scene.settings();
            f.renderer = RendererKind::Reference;
            f.camera.width = f.camera.height = 4 * n;
            f.camera.pixelSize = extent / (4.0 * n);
            truths.push_back(boxDownsample(scene.render(f), 4));
            progress.step("box-filtered reference " + std::to_string(n));
        }
        for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet, RendererKind::Reference}) {
            if (base.mode == RenderMode::Iso && r != RendererKind::Reference) continue;
            ConvergenceSeries ps{"pixel-size", r, {}, {}, 0};
            for (std::size_t i = 0; i < o.sizes.size(); ++i) {
                RenderSettings f = scene.settings();
                f.renderer = r;
                f.camera.width = f.camera.height = o.sizes[i];
                f.camera.pixelSize = extent / o.sizes[i];
                ps.h.push_back(f.camera.pixelSize);
                ps.error.push_back(compareImages(scene.render(f), truths[i]).rmse);
                progress.step(std::string(toString(r)) + " " + std::to_string(o.sizes[i]));
            }
            ps.order = fitOrder(ps.h, ps.error);
            out.push_back(ps);
        }
    }
    return out;
}

}  // namespace splat
