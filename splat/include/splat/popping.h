#pragma once
// Popping-artifact analysis (docs/design.md "Artifact analysis"). A sweep of views
// theta_0 < theta_1 < ... is rendered by each renderer X from one Scene, and per interval
// [theta_n, theta_n+1]:
//   temporal change  T_X(n) = RMS(I_X(theta_n+1) - I_X(theta_n))
//   error            e_X(n) = RMS(D_X(theta_n)),  D_X = I_X - I_ref   (reference in the set)
//   error jump       J_X(n) = RMS(D_X(theta_n+1) - D_X(theta_n))
//   cross jump       C(n)   = RMS(Delta(theta_n+1) - Delta(theta_n)), Delta = I_axis - I_sheet
//                             (cheap detection without the reference)
//   perceptual       FLIP1_X(n) = mean LDR-FLIP between consecutive frames, and mean
//                             LDR-FLIP against the reference (Andersson et al. 2020)
//   temporal FLIP    FLIP_k,X(n) = StopThePop's measure (splat/warp.h): mean LDR-FLIP between
//                             frame n + k and frame n warped to view n + k with the exact flow
//                             of the cameras and the reference's depth (splat/depth.h),
//                             occluded pixels and a border masked; k = 1 and 7
// RMS is over all pixels and the RGB channels of the images composited over the background.
// An event is an interval whose detection signal (J_X with a reference, else C for the
// axis-aligned splatter and T_X otherwise) exceeds the sweep's robust threshold
// max(median + k * MAD, floor * median, precision * peak), MAD scaled to a standard deviation
// (x 1.4826), peak the largest pixel value (RGB) of the sweep's frames: on a smooth scene the
// median is itself at rounding level, and the precision floor keeps rounding from being
// called an event.
// Events are refined by bisection: a renderer pops at theta* when its change stays bounded
// away from zero as the interval shrinks, while a continuous renderer's change falls about
// linearly with it (fitted slope ~1 on log-log axes). Flicker is fast but continuous
// change: the ratio of a renderer's median T to the reference's.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "splat/error.h"
#include "splat/image.h"
#include "splat/scene.h"
#include "splat/sequence.h"
#include "splat/settings.h"
#include "splat/warp.h"

namespace splat {

/// The views of a sweep: the base camera turned about one angle. End points follow the one
/// convention of docs/decisions.md "Sequences": `to` is inclusive, the last view.
struct Sweep {
    enum class Angle { Azimuth, Elevation };
    Angle angle = Angle::Azimuth;
    double from = 40, to = 50, step = 0.5;  ///< degrees; `to` is the last view (inclusive)
    CameraParams base;                      ///< the other camera parameters
    /// The sweep's views: from, from + step, ..., to (the last within step / 1000 of to).
    std::vector<double> angles() const;
    CameraParams camera(double angle) const;
};

struct PoppingOptions {
    std::vector<RendererKind> renderers{RendererKind::Axis, RendererKind::Sheet,
                                        RendererKind::Reference};
    double madK = 5.0;        ///< event threshold: median + madK * MAD ...
    double floorRatio = 2.0;  ///< ... and at least floorRatio * median
    /// ... and above precisionFloor times the sweep's peak pixel value: 1e-6 is about 8 float
    /// ulps (FLT_EPSILON = 1.2e-7) of the peak, above the rounding of a frame's float sums,
    /// and below the smallest visible change (one pixel moving one 8-bit step in a 1024 x
    /// 1024 image is an RMS of 3.8e-6). 0 disables it.
    double precisionFloor = 1e-6;
    int refine = 10;              ///< bisection levels around each event (0: none)
    double pixelsPerDegree = 67;  ///< LDR-FLIP viewing condition
    bool flip = true;             ///< compute the perceptual columns
    /// Compute StopThePop's temporal FLIP_1 and FLIP_7 (with `flip`): one reference depth
    /// per view and two warps per renderer and view, and frame t - 7 kept per renderer.
    bool warpFlip = true;
    WarpOptions warp;  ///< the warp's border and occlusion tolerance
    /// The reference's depth at a view (splat/depth.h) where frames come from renderFrame,
    /// e.g. gaussianReferenceDepth of a Gaussian scene; unset, such an analysis has no
    /// temporal FLIP. The Scene overloads take referenceDepth of the Scene.
    std::function<Image(const CameraParams&)> depthFrame;
    int thumbnail = 160;          ///< longest side of the animation frames kept, pixels
    /// Frames rendered at once, each on one thread (0: one per thread for images up to
    /// 256 x 256 and up to 1M splats, else 1: one frame at a time on every thread). The
    /// images are the same.
    int parallelFrames = 0;
    ProgressFn progress;  ///< optional; called after every frame
    /// Folder of the frame journal (empty: none). Every frame rendered is stored there
    /// (pixels bit for bit, its time, size and checksum), and a frame found there whole is
    /// read back instead of rendered: an interrupted analysis resumes with the images of an
    /// uninterrupted one. The folder must exist; the caller empties it when the scene, the
    /// sweep or the renderers change. Costs width x height x 16 bytes per frame.
    std::string frameJournal;
    /// Renders one frame (the settings' camera and renderer) instead of the Scene, e.g. from
    /// bricks (splat/bricks.h BrickedFrames; `splat popping --bricks K`). Set: every frame is
    /// rendered through it, one after another (parallelFrames does not apply). The findings
    /// depend only on the images.
    std::function<Image(const RenderSettings&, RenderStats*)> renderFrame;
    /// The renderers' names in the report, summary.json, metrics.csv and the journal
    /// (`renderers` order; empty: their kinds' names). Named renderers may share a kind (the
    /// kind is their role: Reference the truth, Axis and Sheet the cross jump's pair), e.g. a
    /// Gaussian scene's 3dgs and 3dgs-pixel both as Axis (splat/gaussian_popping.h); their
    /// frames come from renderNamed.
    std::vector<std::string> names;
    /// Renders one frame of renderer `index` (into `renderers`); set, it is used instead of
    /// renderFrame, as renderFrame is.
    std::function<Image(std::size_t index, const RenderSettings&, RenderStats*)> renderNamed;
    /// The positions where a renderer is predicted to pop, and what the report calls them,
    /// instead of the axis-aligned splatter's sheet switches (e.g. a Gaussian scene's order
    /// swaps, predictOrderSwaps in splat/gaussian_popping.h).
    std::optional<std::vector<double>> predicted;
    std::string predictedName = "sheet switch";
    /// How the report describes the scene (empty: the settings' mode, transfer function,
    /// classification and kernel).
    std::string scene;
    /// The reference e, J and flipRef are measured against (truthFilter, splat/render.h):
    /// auto (the default) the pixel-filtered reference where the splatters' frames are
    /// filtered (EWA on at some view of the sweep, e.g. X-ray below a pixel per voxel, or a
    /// pixel filter given), else the point-sampled one. The reference's frames get that
    /// pixel filter; the splatters' frames the settings' own. Where the Scene's settings
    /// (poppingSettings) carry it, the sweep renders as fast as without; else view by view.
    /// With renderFrame, the frames are what it renders (build it from poppingSettings).
    Truth truth = Truth::Auto;
};

/// A change measured at one interval width while refining an event.
struct RefinementStep {
    double width = 0;  ///< degrees
    double from = 0;   ///< the refined interval [from, from + width]
    /// Per renderer (PoppingResult::renderers order): T over the interval, and J when the
    /// reference is in the set (else 0).
    std::vector<double> change, jump;
};

/// Frames of the views on both sides of an event, per renderer (full resolution).
struct EventFrames {
    std::vector<Image> before, after;  ///< PoppingResult::renderers order
};

struct PoppingEvent {
    RendererKind renderer = RendererKind::Axis;  ///< whose signal fired
    std::size_t series = 0;                      ///< its index in PoppingResult::series
    double angleFrom = 0, angleTo = 0;           ///< the sweep interval
    double signal = 0;                           ///< J (or C, or T) over it
    /// Refinement: the change at the finest width, the finest width, and the slope of
    /// log(change) against log(width) fitted over the refinement steps (~0: a
    /// discontinuity; ~1: continuous change).
    double refinedJump = 0, refinedWidth = 0, refinedSlope = 0, refinedAngle = 0;
    std::vector<RefinementStep> refinement;
    /// Axis-aligned splatter's sheet axis (0, 1, 2; -1 for others) and sign before and after.
    int sheetAxisBefore = -1, sheetAxisAfter = -1, sheetSignBefore = 0, sheetSignAfter = 0;
    bool predicted = false;  ///< a predicted sheet switch lies in [angleFrom, angleTo]
    EventFrames frames;      ///< at angleFrom and angleTo
};

/// Everything measured for one renderer over the sweep.
struct RendererSeries {
    RendererKind renderer = RendererKind::Axis;
    std::string name;  ///< PoppingOptions::names, else the kind's name
    /// Per interval n (angles.size() - 1 entries).
    std::vector<double> T, J, flipT;
    /// StopThePop's FLIP_1 per interval n (frame n warped to n + 1) and FLIP_7 per pair
    /// (n, n + 7) (angles.size() - 7 entries; none for sweeps of fewer than 8 views); -1 where
    /// no pixel is valid. Empty when not measured (PoppingOptions::warpFlip, no depth).
    std::vector<double> flipWarp1, flipWarp7;
    /// Their means over the pairs with valid pixels; -1 when not measured.
    double flipWarp1Mean = -1, flipWarp7Mean = -1;
    /// Per view n (angles.size() entries): error against the reference and its mean FLIP.
    std::vector<double> e, flipRef;
    std::vector<int> sheetAxis, sheetSign;  ///< per view (axis-aligned; else -1, 0)
    /// Per view: pixels the splatter handed to the reference (RenderStats::exactPixels; 0
    /// for the reference itself). A view with exact pixels compares the reference with
    /// itself there; the report marks it.
    std::vector<std::size_t> exactPixels;
    std::string exactReason;     ///< the first such view's RenderStats::exactReason
    std::vector<double> signal;  ///< the detection signal per interval
    double threshold = 0, medianSignal = 0, spikeRatio = 0;  ///< max signal / median
    double medianT = 0, flickerRatio = 0;  ///< median T / reference's median T (0 without)
    double msPerFrame = 0, totalMs = 0;    ///< median frame time, total render time
    std::vector<Image> thumbnails;         ///< per view, for the side-by-side animation
};

struct PoppingResult {
    /// The sweep analysed; for a camera path (pathViews > 0) unused.
    Sweep sweep;
    /// Views of the camera path analysed; 0 for a sweep. For a path, `angles` and every
    /// angle of the result (events, refinement, predicted switches) are path positions u:
    /// view n at u = n, a fractional u the camera interpolated between views floor(u) and
    /// floor(u) + 1 (interpolateCamera).
    std::size_t pathViews = 0;
    PoppingOptions options;   ///< as used (progress omitted)
    RenderSettings settings;  ///< the scene's settings
    std::vector<RendererKind> renderers;
    std::vector<double> angles;
    std::vector<RendererSeries> series;     ///< renderers order
    std::vector<double> crossJump;          ///< C per interval (axis and sheet both present)
    /// Angles where the sheet axis changes, or PoppingOptions::predicted (options.predictedName
    /// says which).
    std::vector<double> predictedSwitches;
    std::vector<PoppingEvent> events;
    /// The pixel filter sigma of the reference's frames, pixels: 0 the point-sampled
    /// reference (one ray per pixel centre), > 0 the pixel-filtered one (PoppingOptions::truth).
    double truthFilter = 0;
    double totalMs = 0;
    const RendererSeries* find(RendererKind k) const;
};

/// Renders the sweep with every renderer of `options` from `scene`, measures, detects and
/// refines events. Throws splat::Error on bad sweeps, splat::Cancelled when cancelled.
/// Progress: `total` is the sweep's frames (views x renderers) until the events are found,
/// then grows once, by the refinement's frames (events x (refine + 2) x renderers), and
/// stays; `done` never exceeds it. Cancel reaches inside the frame in flight.
PoppingResult analyzePopping(const Scene& scene, const Sweep& sweep, const PoppingOptions& options);
/// The same with frames from options.renderFrame (required) of a volume of geometry
/// `geometry` (dims, spacing, origin, direction; no samples needed) and `settings` (the
/// Scene's settings).
PoppingResult analyzePopping(const Volume& geometry, const RenderSettings& settings,
                             const Sweep& sweep, const PoppingOptions& options);
/// The same over any camera path (at least 3 views; every view of the same image size and
/// projection, all orbit or all free cameras): interval n lies between views n and n + 1,
/// thresholds and report as for a sweep; refinement bisects an interval in path position,
/// rendering the camera interpolated between its two views (interpolateCamera).
PoppingResult analyzePopping(const Scene& scene, const CameraPath& path,
                             const PoppingOptions& options);
/// The same over a camera path with frames from options.renderFrame (required) of a volume
/// of geometry `geometry` and `settings` (as the sweep's overload above).
PoppingResult analyzePopping(const Volume& geometry, const RenderSettings& settings,
                             const CameraPath& path, const PoppingOptions& options);
/// The same over explicit cameras.
PoppingResult analyzePopping(const Scene& scene, const std::vector<CameraParams>& views,
                             const PoppingOptions& options);

/// `settings` with the pixel filter of the reference that `truth` asks for at `views` over
/// `volume` (truthFilter, splat/render.h), to build the analysis's Scene (or bricks) with:
/// the splatters' frames do not change (their EWA low-pass is that sigma either way), and
/// the sweep renders its views in parallel. Unchanged where the truth is point-sampled.
RenderSettings poppingSettings(const RenderSettings& settings, const Volume& volume,
                               const std::vector<CameraParams>& views, Truth truth);

/// The angles in (from, to) where the axis-aligned splatter's sheet axis (the major axis of
/// S^-1 view) changes along the sweep, to 1e-9 degrees.
std::vector<double> predictSheetSwitches(const Sweep& sweep, const Volume& volume);
/// The path positions u where the sheet axis changes along a camera path (views at u = n).
std::vector<double> predictSheetSwitches(const CameraPath& path, const Volume& volume);

/// Writes `dir`/report.html (self-contained: inline SVG plots, embedded images and
/// animation), metrics.csv (one row per renderer and interval) and summary.json (schema in
/// docs/popping.md "Popping reports: summary.json"), each atomically. `commandLine` is shown
/// in the report (how to reproduce it).
void writePoppingReport(const PoppingResult& result, const std::string& dir,
                        const std::string& commandLine);

}  // namespace splat
