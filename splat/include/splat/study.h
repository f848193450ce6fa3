#pragma once
// Speed-accuracy studies: render a volume under every combination of the
// swept knobs that trade speed for accuracy, time each setting (median over repeats
// after a warm-up), measure its peak memory, splat count and footprint-pixel rate, and
// its error against the reference ray caster of the same model (RMSE, PSNR, max, mean
// LDR-FLIP when splat/flip.h is available); mark the Pareto-optimal settings (no other
// setting is both faster and more accurate). Also the observed convergence orders of
// each renderer's error (Etiene et al. 2009) as the slab thins, the reference step and
// the pixel size shrink.
//
// Knobs (names as on the command line, `--sweep NAME=V1,V2,...`):
//   per frame (one Scene serves them):  renderer, quality (fast|default|exact: the preset's
//                                       knobs), slab, early-termination, size (WxH or N),
//                                       order, lod, ewa (off|on|auto), pixel-filter (the
//                                       reference is filtered through it too)
//   per Scene (a new Scene per value):  classify, kernel, sigma, radius, footprint-res,
//                                       slab-radial-res, slab-depth-res, poly-tol
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "splat/image.h"
#include "splat/sequence.h"
#include "splat/settings.h"
#include "splat/volume.h"

namespace splat {

/// One swept knob and its values (as text, parsed by applyKnob).
struct StudyKnob {
    std::string name;
    std::vector<std::string> values;
};

/// Knob names accepted by a study.
std::vector<std::string> studyKnobNames();
/// True for knobs that need a new Scene per value.
bool isSceneKnob(const std::string& name);
/// Sets knob `name` to `value` in `s`; throws splat::Error for an unknown knob or value.
void applyKnob(RenderSettings& s, const std::string& name, const std::string& value);
/// "slab=2,1,0.5" -> {slab, {2, 1, 0.5}}; throws splat::Error on malformed text.
StudyKnob parseKnob(const std::string& text);

struct StudyOptions {
    std::vector<StudyKnob> sweeps;  ///< the settings are every combination of their values
    /// Views (camera azimuth, elevation of the base camera); empty: the base camera alone.
    std::vector<glm::dvec2> views;
    int repeats = 5, warmup = 1;  ///< timed frames per setting and view, after the warm-up
    /// The reference is rendered once per view and image size, with the base settings'
    /// scene knobs (the model the study measures against) and its own step/tolerance.
    double referenceStep = 0.125, referenceTolerance = 1e-5;
    /// Folder where references are cached as EXR (keyed by view, size and settings);
    /// empty: no cache.
    std::string cacheDir;
    double pixelsPerDegree = 67;  ///< LDR-FLIP viewing condition
    ProgressFn progress;          ///< called after every rendered frame
    /// JSON file of the points measured so far (empty: none), rewritten atomically after
    /// each point; a point found there (by label) is not measured again, so an interrupted
    /// study resumes where it stopped. The caller removes it when the study changes.
    std::string pointJournal;
    /// The reference each point is judged against (truthFilter, splat/render.h): auto (the
    /// default) the pixel-filtered reference where the point's frames are filtered (EWA on,
    /// e.g. xray below a pixel per voxel, or a pixel filter given), else the point-sampled
    /// one; point always at the pixel centres; filtered always through the pixel filter.
    Truth truth = Truth::Auto;
    /// Also measure the three quality presets (`--quality`, splat/options.h) on the base
    /// settings, as the points quality=fast, quality=default and quality=exact (the report's
    /// plot marks them), unless a sweep varies quality itself.
    bool presets = false;
};

/// One setting of the study.
struct StudyPoint {
    std::vector<std::pair<std::string, std::string>> knobs;  ///< knob = value, sweep order
    RenderSettings settings;
    double msMedian = 0, msMin = 0, msMax = 0;  ///< over repeats and views
    double msMad = 0;                           ///< median absolute deviation (spread)
    double peakMiB = 0;               ///< peak resident memory while rendering it (Linux; else 0)
    std::size_t splats = 0;           ///< splats in the list
    std::size_t footprintPixels = 0;  ///< footprint-pixel updates per frame (first view)
    double footprintPixelRate = 0;    ///< footprint-pixel updates per second
    /// Error against the reference, averaged over views (psnr: from the mean rmse).
    double rmse = 0, psnr = 0, maxAbs = 0;
    double flip = NAN;  ///< mean LDR-FLIP (NaN when splat/flip.h is not built in)
    bool pareto = false;
    /// Frames (views x repeats) whose pixels the splatter handed to the reference
    /// (RenderStats::exactPixels > 0): their error says nothing about the splatter.
    std::size_t exactFrames = 0;
    /// The pixel filter sigma of the reference it was judged against, pixels (0: the
    /// point-sampled reference; StudyOptions::truth), the largest over the views.
    double truthFilter = 0;
    std::string label() const;  ///< "renderer=sheet slab=0.5"
};

/// A renderer's error against a finer solution as one discretisation parameter h shrinks,
/// and the observed order: the slope of log(error) against log(h), least squares.
struct ConvergenceSeries {
    std::string parameter;  ///< "slab", "reference-step", "pixel-size"
    RendererKind renderer = RendererKind::Sheet;
    std::vector<double> h, error;
    double order = 0;
};

struct StudyResult {
    RenderSettings base;
    StudyOptions options;  ///< as used (progress omitted)
    std::string volume;    ///< description of the volume
    std::size_t visibleVoxels = 0;
    std::vector<StudyPoint> points;
    std::vector<ConvergenceSeries> convergence;
    double totalMs = 0;
    bool flipAvailable = false;
};

/// The settings of the study's reference frames: the base model (its scene knobs) with the
/// reference ray caster at the options' step and tolerance, seen by `camera`, filtered through
/// `frame`'s pixel filter when given (else the base's). The processes of a frame farm
/// (splat/frame_farm.h) render the references from a Scene of these.
RenderSettings studyReferenceSettings(const RenderSettings& base, const StudyOptions& options,
                                      const CameraParams& camera, const Quality* frame = nullptr);

/// Runs the study on `volume`. Throws splat::Error on bad knobs, splat::Cancelled when
/// progress returns false. With a frame farm installed (splat/frame_farm.h, e.g. under
/// mpirun), the references missing from the cache are rendered on the farm first, before
/// any frame is timed; the timed frames are rendered here alone.
StudyResult runStudy(std::shared_ptr<const Volume> volume, const RenderSettings& base,
                     const StudyOptions& options);

/// Observed orders for the splatters and the reference (appended to result.convergence):
/// slab (image-aligned splatter; slabs `slabs`), reference step (reference against its own
/// finest step) and pixel size (each renderer at N, 2N, 4N pixels against the reference
/// box-filtered from 4x as many pixels per side).
struct ConvergenceOptions {
    std::vector<double> slabs{2, 1, 0.5, 0.25};
    std::vector<double> referenceSteps{1, 0.5, 0.25, 0.125};
    std::vector<int> sizes{24, 48, 96};
    ProgressFn progress;
};
std::vector<ConvergenceSeries> studyConvergence(std::shared_ptr<const Volume> volume,
                                                const RenderSettings& base,
                                                const ConvergenceOptions& options);

/// Least-squares slope of log(error) against log(h) (points with error <= 0 are skipped).
double fitOrder(const std::vector<double>& h, const std::vector<double>& error);

/// Marks StudyPoint::pareto: minimal in (msMedian, rmse).
void markPareto(std::vector<StudyPoint>& points);

/// Writes `dir`/study.csv, study.json, pareto.svg and pareto.png (error against time, log
/// axes, Pareto front joined), each atomically.
void writeStudyReport(const StudyResult& result, const std::string& dir,
                      const std::string& commandLine);

/// Box-filters `image` by an integer factor (each output pixel the mean of f x f pixels).
Image boxDownsample(const Image& image, int factor);

}  // namespace splat
