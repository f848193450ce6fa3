// Popping-artifact analysis (see splat/popping.h and docs/design.md "Artifact analysis").
#include "splat/popping.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <numeric>

#include "frame/stopwatch.h"
#include "analysis/flip_image.h"
#include "analysis/median.h"
#include "analysis/temporal_flip.h"
#include "frame_journal.h"
#include "splat/flip.h"
#include "splat/image_io.h"
#include "splat/render.h"
#include "splatters/splatter.h"

namespace splat {

namespace {

constexpr std::size_t kMaxViews = 100000;

/// RMS over pixels and RGB of (a - b) - (c - d); c, d may be null (then of a - b).
double rmsDiff(const Image& a, const Image& b, const Image* c = nullptr, const Image* d = nullptr) {
    double sum = 0;
    const std::size_t n = a.pixels.size();
    for (std::size_t p = 0; p < n; ++p)
        for (int ch = 0; ch < 3; ++ch) {
            double v = double(a.pixels[p][ch]) - double(b.pixels[p][ch]);
            if (c && d) v -= double(c->pixels[p][ch]) - double(d->pixels[p][ch]);
            sum += v * v;
        }
    return n ? std::sqrt(sum / double(3 * n)) : 0.0;
}

using analysis::median;

/// median + k * MAD (scaled to a standard deviation), and at least floor * median.
double robustThreshold(const std::vector<double>& s, double k, double floorRatio) {
    const double med = median(s);
    std::vector<double> dev(s.size());
    for (std::size_t n = 0; n < s.size(); ++n) dev[n] = std::abs(s[n] - med);
    const double mad = 1.4826 * median(dev);
    return std::max(med + k * mad, floorRatio * med);
}

/// The renderers' names: PoppingOptions::names (one per renderer), else the kinds' names.
std::vector<std::string> rendererNames(const PoppingOptions& options) {
    if (options.names.empty()) {
        std::vector<std::string> out;
        for (RendererKind k : options.renderers) out.push_back(toString(k));
        return out;
    }
    if (options.names.size() != options.renderers.size())
        throw Error("popping: " + std::to_string(options.names.size()) + " names for " +
                    std::to_string(options.renderers.size()) + " renderers");
    return options.names;
}

/// One view rendered by every renderer; a sweep's views with FLIP also the frames as FLIP
/// perceives them (each compared with the reference, the previous view and its warped past).
struct View {
    std::vector<Image> images;
    std::vector<RenderStats> stats;
    std::vector<analysis::FlipImage> perceived;
};

class Analyzer {
  public:
    /// `positions` are the views' sweep angles or path positions, `cameraAt` the camera at
    /// any position between the first and the last.
    /// `scene` null: frames from options.renderFrame, of `settings`.
    Analyzer(const Scene* scene, const Volume& geometry, const RenderSettings& settings,
             const Sweep& sweep, std::size_t pathViews, std::vector<double> positions,
             std::function<CameraParams(double)> cameraAt, std::vector<double> predicted,
             const PoppingOptions& options)
        : scene_(scene),
          settings_(settings),
          sweep_(sweep),
          pathViews_(pathViews),
          positions_(std::move(positions)),
          predicted_(options.predicted ? *options.predicted : std::move(predicted)),
          cameraAt_(std::move(cameraAt)),
          options_(options),
          temporal_(options, geometry, scene) {
        kinds_ = options.renderers;
        if (kinds_.empty()) throw Error("popping: no renderer to analyse");
        if (!scene_ && !options.renderFrame && !options.renderNamed)
            throw Error("popping: no Scene and no renderFrame");
        names_ = rendererNames(options);
        for (std::size_t i = 0; i < kinds_.size(); ++i)
            for (std::size_t j = 0; j < i; ++j)
                if (names_[i] == names_[j])
                    throw Error("popping: renderer '" + names_[i] + "' listed twice");
        if (std::count(kinds_.begin(), kinds_.end(), RendererKind::Reference) > 1)
            throw Error("popping: more than one renderer in the reference's role");
        ref_ = indexOf(RendererKind::Reference);
        axis_ = indexOf(RendererKind::Axis);
        sheet_ = indexOf(RendererKind::Sheet);
        if (!(options.madK >= 0) || !(options.floorRatio >= 0) || !(options.precisionFloor >= 0))
            throw Error("popping: the event threshold's k and floors must be >= 0");
        if (options.refine < 0 || options.refine > 40)
            throw Error("popping: --refine must be between 0 and 40 levels");
        std::vector<CameraParams> views;
        for (double p : positions_) views.push_back(cameraAt_(p));
        truthFilter_ = truthFilter(settings_, geometry, views, options.truth);
    }

    PoppingResult run() {
        const auto start = Clock::now();
        PoppingResult r;
        r.sweep = sweep_;
        r.pathViews = pathViews_;
        r.options = options_;
        r.options.progress = nullptr;
        r.settings = settings_;
        r.renderers = kinds_;
        r.angles = positions_;
        r.predictedSwitches = predicted_;
        r.truthFilter = ref_ >= 0 ? truthFilter_ : 0;
        const std::size_t views = r.angles.size();
        totalUnits_ = views * kinds_.size();
        const CameraParams& base = cameraAt_(r.angles.front());
        r.series.resize(kinds_.size());
        for (std::size_t k = 0; k < kinds_.size(); ++k) {
            r.series[k].renderer = kinds_[k];
            r.series[k].name = names_[k];
        }

        std::vector<std::vector<double>> frameMs(kinds_.size());
        CameraPath path;
        for (double angle : r.angles) path.views.push_back(cameraAt_(angle));
        SequenceOptions so;
        so.parallelFrames = options_.parallelFrames;
        std::size_t sequenceDone = 0;
        so.progress = [&](std::size_t done, std::size_t, const std::string& what) {
            if (done > sequenceDone) {  // a frame finished
                sequenceDone = done;
                report(what);
            } else {  // a tile of the frame in flight
                poll(what);
            }
            return !cancelled_;
        };
        // Views whose frames are all in the journal are read back, not rendered.
        std::vector<bool> journaled(views, false);
        for (std::size_t v = 0; v < views && !options_.frameJournal.empty(); ++v) {
            journaled[v] = true;
            for (std::size_t k = 0; k < kinds_.size(); ++k)
                journaled[v] = journaled[v] && journal::hasFrame(journalFile(r.angles[v], k),
                                                                 base.width, base.height);
        }
        so.skip = [&](std::size_t v) { return bool(journaled[v]); };
        View prev;
        std::size_t next = 0;
        double peak = 0;  // the largest pixel value (RGB) of the sweep's frames
        auto consume = [&](std::size_t v, View cur) {
            if (v == 0) setWindow(cur);
            for (const Image& im : cur.images)
                for (const glm::vec4& p : im.pixels)
                    peak = std::max({peak, double(std::abs(p.r)), double(std::abs(p.g)),
                                     double(std::abs(p.b))});
            perceive(cur);
            measureView(r, v, cur, prev, frameMs);
            measureWarped(r, v, cur);
            prev = std::move(cur);
            next = v + 1;
        };
        auto readUpTo = [&](std::size_t end) {
            while (next < end) consume(next, renderView(r.angles[next]));
        };
        // The Scene renders the sweep (in parallel) when its reference is the truth asked
        // for; else, and with renderFrame, every view by renderView, below.
        const bool sceneTruth =
            ref_ < 0 || (scene_ && scene_->settings().quality.pixelFilter == truthFilter_);
        if (!options_.renderFrame && !options_.renderNamed && sceneTruth)
            renderSequence(*scene_, kinds_, path, so, [&](SequenceFrame&& f) {
                readUpTo(f.view);
                View cur{std::move(f.images), std::move(f.stats), {}};
                if (!options_.frameJournal.empty())
                    for (std::size_t k = 0; k < kinds_.size(); ++k)
                        journal::storeFrame(journalFile(r.angles[f.view], k), cur.images[k],
                                            cur.stats[k]);
                consume(f.view, std::move(cur));
            });
        readUpTo(views);
        for (std::size_t k = 0; k < kinds_.size(); ++k) {
            RendererSeries& s = r.series[k];
            s.msPerFrame = median(frameMs[k]);
            s.medianT = median(s.T);
            s.signal = signalOf(r, k);
            s.medianSignal = median(s.signal);
            s.threshold = std::max(robustThreshold(s.signal, options_.madK, options_.floorRatio),
                                   options_.precisionFloor * peak);
            const double mx = *std::max_element(s.signal.begin(), s.signal.end());
            s.spikeRatio = s.medianSignal > 0 ? mx / s.medianSignal : (mx > 0 ? INFINITY : 1.0);
        }
        temporal_.finish(r.series);
        if (ref_ >= 0)
            for (RendererSeries& s : r.series)
                s.flickerRatio =
                    r.series[ref_].medianT > 0 ? s.medianT / r.series[ref_].medianT : 0;
        std::vector<std::pair<std::size_t, std::size_t>> found;
        for (std::size_t k = 0; k < kinds_.size(); ++k)
            for (std::size_t n = 0; n < r.series[k].signal.size(); ++n)
                if (r.series[k].signal[n] > r.series[k].threshold) found.emplace_back(k, n);
        {
            // The refinement's frames are known now: the total grows once, here.
            std::lock_guard<std::mutex> lock(progressMutex_);
            totalUnits_ = done_ + found.size() * std::size_t(options_.refine + 2) * kinds_.size();
        }
        refineEvents(r, found);
        r.totalMs = msSince(start);
        return r;
    }

    /// The events of `found` (renderer, interval) into r.events, in that order, refined
    /// interval by interval: every renderer's event on one interval bisects through the same
    /// views while its choices agree, and neighbouring intervals share their common end, so a
    /// view is rendered once for all of them (held until the next interval starts).
    void refineEvents(PoppingResult& r,
                      const std::vector<std::pair<std::size_t, std::size_t>>& found) {
        std::vector<std::size_t> order(found.size());
        std::iota(order.begin(), order.end(), std::size_t(0));
        std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
            return found[a].second < found[b].second;
        });
        r.events.resize(found.size());
        for (const std::size_t i : order) {
            const std::size_t n = found[i].second;
            const double lo = std::min(r.angles[n], r.angles[n + 1]),
                         hi = std::max(r.angles[n], r.angles[n + 1]);
            std::erase_if(views_, [&](const auto& kv) { return kv.first < lo || kv.first > hi; });
            r.events[i] = event(r, found[i].first, n);
        }
        views_.clear();
    }

    void measureView(PoppingResult& r, std::size_t n, const View& cur, const View& prev,
                     std::vector<std::vector<double>>& frameMs) const {
        for (std::size_t k = 0; k < kinds_.size(); ++k) {
            RendererSeries& s = r.series[k];
            frameMs[k].push_back(cur.stats[k].milliseconds);
            s.totalMs += cur.stats[k].milliseconds;
            s.sheetAxis.push_back(cur.stats[k].sheetAxis);
            s.sheetSign.push_back(cur.stats[k].sheetSign);
            s.exactPixels.push_back(
                kinds_[k] == RendererKind::Reference ? 0 : cur.stats[k].exactPixels);
            if (s.exactReason.empty() && s.exactPixels.back() > 0)
                s.exactReason = cur.stats[k].exactReason;
            s.thumbnails.push_back(downscale(cur.images[k], options_.thumbnail));
            if (ref_ >= 0) {
                s.e.push_back(rmsDiff(cur.images[k], cur.images[ref_]));
                // FLIP of identical images is exactly 0 (splat/flip.h).
                s.flipRef.push_back(int(k) == ref_ ? 0.0 : flip(cur, cur, k, ref_));
            }
            if (n > 0) {
                s.T.push_back(rmsDiff(cur.images[k], prev.images[k]));
                s.flipT.push_back(flip(cur, prev, k, k));
                if (ref_ >= 0)
                    s.J.push_back(rmsDiff(cur.images[k], cur.images[ref_], &prev.images[k],
                                          &prev.images[ref_]));
            }
        }
        if (n > 0 && axis_ >= 0 && sheet_ >= 0)
            r.crossJump.push_back(rmsDiff(cur.images[axis_], cur.images[sheet_],
                                          &prev.images[axis_], &prev.images[sheet_]));
    }

    /// StopThePop's FLIP_1 and FLIP_7 of view n (splat/warp.h), on the frames as FLIP sees
    /// them.
    void measureWarped(PoppingResult& r, std::size_t n, const View& cur) {
        if (!temporal_.enabled()) return;
        std::vector<Image> shown;
        for (const Image& im : cur.images) shown.push_back(display(im));
        temporal_.addView(n, cameraAt_(r.angles[n]), shown, cur.perceived, r.series);
    }

  private:
    int indexOf(RendererKind k) const {
        for (std::size_t i = 0; i < kinds_.size(); ++i)
            if (kinds_[i] == k) return int(i);
        return -1;
    }

    /// The detection signal of renderer k per interval.
    std::vector<double> signalOf(const PoppingResult& r, std::size_t k) const {
        if (ref_ >= 0 && int(k) != ref_) return r.series[k].J;
        if (ref_ < 0 && int(k) == axis_ && sheet_ >= 0) return r.crossJump;
        return r.series[k].T;
    }

    /// The detection measure of renderer k between two views.
    double measure(std::size_t k, const View& a, const View& b) const {
        if (ref_ >= 0 && int(k) != ref_)
            return rmsDiff(b.images[k], b.images[ref_], &a.images[k], &a.images[ref_]);
        if (ref_ < 0 && int(k) == axis_ && sheet_ >= 0)
            return rmsDiff(b.images[axis_], b.images[sheet_], &a.images[axis_], &a.images[sheet_]);
        return rmsDiff(b.images[k], a.images[k]);
    }

    RefinementStep step(const View& a, const View& b, double from, double width) const {
        RefinementStep st;
        st.from = from;
        st.width = width;
        for (std::size_t k = 0; k < kinds_.size(); ++k) {
            st.change.push_back(rmsDiff(b.images[k], a.images[k]));
            st.jump.push_back(
                ref_ >= 0 ? rmsDiff(b.images[k], b.images[ref_], &a.images[k], &a.images[ref_])
                          : 0.0);
        }
        return st;
    }

    PoppingEvent event(const PoppingResult& r, std::size_t k, std::size_t n) {
        PoppingEvent ev;
        ev.renderer = kinds_[k];
        ev.series = k;
        ev.angleFrom = r.angles[n];
        ev.angleTo = r.angles[n + 1];
        ev.signal = r.series[k].signal[n];
        if (axis_ >= 0) {
            ev.sheetAxisBefore = r.series[axis_].sheetAxis[n];
            ev.sheetAxisAfter = r.series[axis_].sheetAxis[n + 1];
            ev.sheetSignBefore = r.series[axis_].sheetSign[n];
            ev.sheetSignAfter = r.series[axis_].sheetSign[n + 1];
        }
        for (double s : r.predictedSwitches)
            if (s >= ev.angleFrom && s <= ev.angleTo) ev.predicted = true;
        // Proof of discontinuity: bisect towards the half where the measure is larger.
        double a = ev.angleFrom, b = ev.angleTo;
        View va = viewAt(a), vb = viewAt(b);
        ev.frames.before = va.images;
        ev.frames.after = vb.images;
        ev.refinement.push_back(step(va, vb, a, b - a));
        for (int level = 0; level < options_.refine; ++level) {
            const double m = 0.5 * (a + b);
            View vm = viewAt(m);
            if (measure(k, va, vm) >= measure(k, vm, vb)) {
                b = m;
                vb = std::move(vm);
            } else {
                a = m;
                va = std::move(vm);
            }
            ev.refinement.push_back(step(va, vb, a, b - a));
        }
        const RefinementStep& last = ev.refinement.back();
        ev.refinedJump = ref_ >= 0 && int(k) != ref_ ? last.jump[k] : measure(k, va, vb);
        ev.refinedWidth = last.width;
        ev.refinedAngle = 0.5 * (a + b);
        // Least-squares slope of log(measure) against log(width).
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        int cnt = 0;
        for (const RefinementStep& st : ev.refinement) {
            const double v = ref_ >= 0 && int(k) != ref_ ? st.jump[k] : st.change[k];
            if (!(v > 0)) continue;
            const double x = std::log(st.width), y = std::log(v);
            sx += x;
            sy += y;
            sxx += x * x;
            sxy += x * y;
            ++cnt;
        }
        if (cnt >= 2 && cnt * sxx - sx * sx > 0)
            ev.refinedSlope = (cnt * sxy - sx * sy) / (cnt * sxx - sx * sx);
        return ev;
    }

    /// The journal's file for renderer k's frame at `angle` (the angle's exact bits).
    std::filesystem::path journalFile(double angle, std::size_t k) const {
        std::uint64_t bits;
        std::memcpy(&bits, &angle, sizeof bits);
        char name[64];
        std::snprintf(name, sizeof name, "%s_%016llx.frame", names_[k].c_str(),
                      static_cast<unsigned long long>(bits));
        return std::filesystem::path(options_.frameJournal) / name;
    }

    /// A refinement view: the one already rendered at `angle` for another event (views_),
    /// else renderView's. Frames are deterministic, so the images are the same either way;
    /// a reused view still counts its frames as done.
    View viewAt(double angle) {
        const auto it = views_.find(angle);
        if (it == views_.end()) return views_.emplace(angle, renderView(angle)).first->second;
        for (std::size_t k = 0; k < kinds_.size(); ++k)
            report(std::string(toString(kinds_[k])) + " at " + std::to_string(angle));
        if (cancelled_) throw Cancelled();
        return it->second;
    }

    /// Every renderer's frame of one view (refinement, and sweep views in the journal):
    /// read back from the journal when there whole, else rendered (and journaled).
    View renderView(double angle) {
        View v;
        v.images.resize(kinds_.size());
        v.stats.resize(kinds_.size());
        RenderSettings s = settings_;
        s.camera = cameraAt_(angle);
        s.progress = [this](std::size_t, std::size_t, const std::string& what) {
            poll(what);
            return !cancelled_;
        };
        const bool journaling = !options_.frameJournal.empty();
        for (std::size_t k = 0; k < kinds_.size(); ++k) {
            s.renderer = kinds_[k];
            s.quality.pixelFilter = kinds_[k] == RendererKind::Reference
                                        ? truthFilter_
                                        : settings_.quality.pixelFilter;
            const std::filesystem::path file = journaling ? journalFile(angle, k) : "";
            if (!journaling || !journal::loadFrame(file, s.camera.width, s.camera.height,
                                                   v.images[k], v.stats[k])) {
                v.images[k] = options_.renderNamed   ? options_.renderNamed(k, s, &v.stats[k])
                              : options_.renderFrame ? options_.renderFrame(s, &v.stats[k])
                                                     : scene_->render(s, &v.stats[k]);
                if (journaling) journal::storeFrame(file, v.images[k], v.stats[k]);
            }
            report(names_[k] + " at " + std::to_string(angle));
        }
        if (cancelled_) throw Cancelled();
        return v;
    }

    /// One frame done: tell the progress callback (serialised), remember a cancellation.
    void report(const std::string& what) {
        std::lock_guard<std::mutex> lock(progressMutex_);
        ++done_;
        if (options_.progress && !options_.progress(done_, totalUnits_, what)) cancelled_ = true;
    }

    /// Inside a frame: ask the progress callback again (same done and total), so that a
    /// cancel stops the frame in flight.
    void poll(const std::string& what) {
        std::lock_guard<std::mutex> lock(progressMutex_);
        if (!cancelled_ && options_.progress && !options_.progress(done_, totalUnits_, what))
            cancelled_ = true;
    }

    void setWindow(const View& first) {
        const RenderMode mode = settings_.mode;
        if (mode == RenderMode::Dvr || mode == RenderMode::Iso) return;
        float mx = 0;
        for (const Image& im : first.images)
            for (const glm::vec4& p : im.pixels)
                if (std::isfinite(p.r)) mx = std::max(mx, p.r);
        if (mx > 0) windowScale_ = 1.0f / mx;
    }

    /// The frame as FLIP sees it: dvr and iso as they are (linear RGB, clamped by FLIP);
    /// mip and xray scaled to [0, 1] by the sweep's first reference-or-axis frame maximum,
    /// like the windowed PNGs.
    Image display(const Image& im) const {
        if (windowScale_ == 1.0f) return im;
        Image out = im;
        for (glm::vec4& p : out.pixels) p *= windowScale_;
        return out;
    }

    /// The view's frames as FLIP perceives them (shown as display() shows them), once.
    void perceive(View& v) const {
        if (!options_.flip) return;
        FlipOptions fo;
        fo.pixelsPerDegree = options_.pixelsPerDegree;
        for (const Image& im : v.images) v.perceived.emplace_back(display(im), fo);
    }

    /// Mean LDR-FLIP of renderer k's frame of `test` against renderer j's of `reference`.
    double flip(const View& test, const View& reference, std::size_t k, std::size_t j) const {
        if (!options_.flip) return 0;
        return analysis::flipMean(test.perceived[k], reference.perceived[j]);
    }

    const Scene* scene_;
    RenderSettings settings_;
    const Sweep& sweep_;
    std::size_t pathViews_;
    std::vector<double> positions_, predicted_;
    std::function<CameraParams(double)> cameraAt_;
    const PoppingOptions& options_;
    std::vector<RendererKind> kinds_;
    std::vector<std::string> names_;  ///< PoppingOptions::names, else the kinds' names
    int ref_ = -1, axis_ = -1, sheet_ = -1;
    double truthFilter_ = 0;  ///< the reference's pixel filter (PoppingOptions::truth)
    std::size_t done_ = 0, totalUnits_ = 0;
    std::mutex progressMutex_;
    float windowScale_ = 1.0f;
    std::atomic<bool> cancelled_{false};
    analysis::TemporalFlip temporal_;
    std::map<double, View> views_;  ///< refinement views of the interval in hand (viewAt)
};

}  // namespace

std::vector<double> Sweep::angles() const {
    if (!std::isfinite(from) || !std::isfinite(to) || !std::isfinite(step) || !(step > 0))
        throw Error("sweep: --from, --to and --step must be finite, with --step > 0");
    if (to < from) throw Error("sweep: --to must not be below --from");
    const double count = std::floor((to - from) / step + 1e-3) + 1;
    if (count > double(kMaxViews))
        throw Error("sweep: " + std::to_string(count) + " views is more than " +
                    std::to_string(kMaxViews));
    std::vector<double> a(static_cast<std::size_t>(count));
    for (std::size_t n = 0; n < a.size(); ++n) a[n] = from + double(n) * step;
    return a;
}

CameraParams Sweep::camera(double angle) const {
    if (base.lookAtSet)
        throw Error(
            "sweep: a free camera (--eye/--look-at) does not turn; sweeps orbit the "
            "volume centre by azimuth or elevation");
    CameraParams c = base;
    (this->angle == Angle::Azimuth ? c.azimuthDeg : c.elevationDeg) = angle;
    return c;
}

const RendererSeries* PoppingResult::find(RendererKind k) const {
    for (const RendererSeries& s : series)
        if (s.renderer == k) return &s;
    return nullptr;
}

namespace {

/// The camera at path position u: view floor(u) interpolated towards the next.
CameraParams pathCamera(const CameraPath& path, double u) {
    const std::size_t last = path.views.size() - 1;
    if (!(u > 0)) return path.views.front();
    if (u >= double(last)) return path.views.back();
    const std::size_t a = std::min(last - 1, std::size_t(u));
    return interpolateCamera(path.views[a], path.views[a + 1], u - double(a));
}

std::vector<double> pathPositions(const CameraPath& path) {
    if (path.views.size() < 3)
        throw Error("popping: a camera path needs at least 3 views (" +
                    std::to_string(path.views.size()) + " given)");
    if (path.views.size() > kMaxViews)
        throw Error("popping: " + std::to_string(path.views.size()) + " views is more than " +
                    std::to_string(kMaxViews));
    std::vector<double> u(path.views.size());
    for (std::size_t n = 0; n < u.size(); ++n) u[n] = double(n);
    // Every interval must be interpolable (refinement renders between its views).
    for (std::size_t n = 0; n + 1 < u.size(); ++n)
        (void)interpolateCamera(path.views[n], path.views[n + 1], 0.5);
    return u;
}

/// Where the sheet axis changes between consecutive positions, to 1e-9.
std::vector<double> sheetSwitches(const std::vector<double>& positions,
                                  const std::function<CameraParams(double)>& cameraAt,
                                  const Volume& volume) {
    const std::vector<double>& angles = positions;
    auto axisAt = [&](double angle) {
        const Camera cam(cameraAt(angle), volume);
        return sheetAxis(cam.view, volume.spacing).axis;
    };
    std::vector<double> out;
    constexpr int kSub = 16;  // sub-steps per interval, so two switches in one are found
    for (std::size_t n = 0; n + 1 < angles.size(); ++n)
        for (int q = 0; q < kSub; ++q) {
            double a = angles[n] + (angles[n + 1] - angles[n]) * q / kSub;
            double b = angles[n] + (angles[n + 1] - angles[n]) * (q + 1) / kSub;
            const int before = axisAt(a);
            if (axisAt(b) == before) continue;
            while (b - a > 1e-9) {
                const double m = 0.5 * (a + b);
                (axisAt(m) == before ? a : b) = m;
            }
            out.push_back(0.5 * (a + b));
        }
    return out;
}

}  // namespace

RenderSettings poppingSettings(const RenderSettings& settings, const Volume& volume,
                               const std::vector<CameraParams>& views, Truth truth) {
    RenderSettings s = settings;
    const double filter = truthFilter(settings, volume, views, truth);
    if (filter > 0) s.quality.pixelFilter = filter;
    return s;
}

std::vector<double> predictSheetSwitches(const Sweep& sweep, const Volume& volume) {
    return sheetSwitches(
        sweep.angles(), [&](double a) { return sweep.camera(a); }, volume);
}

std::vector<double> predictSheetSwitches(const CameraPath& path, const Volume& volume) {
    return sheetSwitches(
        pathPositions(path), [&](double u) { return pathCamera(path, u); }, volume);
}

PoppingResult analyzePopping(const Scene& scene, const Sweep& sweep,
                             const PoppingOptions& options) {
    std::vector<double> angles = sweep.angles();
    if (angles.size() < 3)
        throw Error("popping: a sweep needs at least 3 views (from, to and step give " +
                    std::to_string(angles.size()) + ")");
    auto cameraAt = [&sweep](double a) { return sweep.camera(a); };
    std::vector<double> predicted = sheetSwitches(angles, cameraAt, scene.volume());
    return Analyzer(&scene, scene.volume(), scene.settings(), sweep, 0, std::move(angles),
                    cameraAt, std::move(predicted), options)
        .run();
}

PoppingResult analyzePopping(const Volume& geometry, const RenderSettings& settings,
                             const Sweep& sweep, const PoppingOptions& options) {
    std::vector<double> angles = sweep.angles();
    if (angles.size() < 3)
        throw Error("popping: a sweep needs at least 3 views (from, to and step give " +
                    std::to_string(angles.size()) + ")");
    auto cameraAt = [&sweep](double a) { return sweep.camera(a); };
    std::vector<double> predicted = sheetSwitches(angles, cameraAt, geometry);
    return Analyzer(nullptr, geometry, settings, sweep, 0, std::move(angles), cameraAt,
                    std::move(predicted), options)
        .run();
}

PoppingResult analyzePopping(const Scene& scene, const CameraPath& path,
                             const PoppingOptions& options) {
    std::vector<double> u = pathPositions(path);
    auto cameraAt = [&path](double x) { return pathCamera(path, x); };
    std::vector<double> predicted = sheetSwitches(u, cameraAt, scene.volume());
    const Sweep none;
    return Analyzer(&scene, scene.volume(), scene.settings(), none, path.views.size(),
                    std::move(u), cameraAt, std::move(predicted), options)
        .run();
}

PoppingResult analyzePopping(const Volume& geometry, const RenderSettings& settings,
                             const CameraPath& path, const PoppingOptions& options) {
    std::vector<double> u = pathPositions(path);
    auto cameraAt = [&path](double x) { return pathCamera(path, x); };
    std::vector<double> predicted = sheetSwitches(u, cameraAt, geometry);
    const Sweep none;
    return Analyzer(nullptr, geometry, settings, none, path.views.size(), std::move(u), cameraAt,
                    std::move(predicted), options)
        .run();
}

PoppingResult analyzePopping(const Scene& scene, const std::vector<CameraParams>& views,
                             const PoppingOptions& options) {
    CameraPath path;
    path.views = views;
    return analyzePopping(scene, path, options);
}

}  // namespace splat
