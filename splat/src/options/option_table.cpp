// The option table (see splat/options.h): every option once, in the order --help lists them
// and scene files hold them, with the rule that says when a run ignores it.
#include <algorithm>

#include "splat/options.h"

namespace splat {

namespace {

using S = RenderSettings;
using U = RenderUse;
using V = OptionValues;

bool projective(const S& s) { return s.mode == RenderMode::Xray || s.mode == RenderMode::Mip; }
bool perspective(const S& s) { return s.camera.projection == Projection::Perspective; }
std::string mode(const S& s) { return toString(s.mode); }
std::string renderer(const S& s) { return toString(s.renderer); }
bool reference(const S& s, const U& u) {
    return u.oneRenderer && s.renderer == RendererKind::Reference;
}
// The splatters hand pixels to the reference ray caster only in perspective views from within
// the volume: the reference's options apply to them there.
bool referenceUnused(const S& s, const U& u) {
    return u.oneRenderer && s.renderer != RendererKind::Reference && !perspective(s);
}
// The shading coefficients without shading: not applicable, or not asked for.
std::string unshaded(const char* flag, const S& s, const V& v) {
    if (v.flag("shade")) return {};
    return std::string(flag) + (projective(s) ? " does not apply to " + mode(s)
                                              : std::string(" given without --shade"));
}
bool eightBit(const std::string& ext) {
    return ext == ".png" || ext == ".gif" || ext == ".jpg" || ext == ".jpeg";
}

std::string ignoredSlab(const S& s, const U& u, const V&) {
    if (!u.oneRenderer || s.renderer == RendererKind::Sheet) return {};
    return "--slab applies to the sheet renderer (image-aligned slabs), not to " + renderer(s);
}
std::string ignoredRefStep(const S& s, const U& u, const V&) {
    if (!referenceUnused(s, u)) return {};
    return "--ref-step applies to the reference renderer, not to " + renderer(s);
}
std::string ignoredRefTolerance(const S& s, const U& u, const V&) {
    if (!referenceUnused(s, u)) return {};
    return "--ref-tolerance applies to the reference renderer, not to " + renderer(s);
}
std::string ignoredTileSize(const S& s, const U& u, const V&) {
    if (!reference(s, u)) return {};
    return "--tile-size applies to the splatters, not to the reference renderer";
}
std::string ignoredEarlyTermination(const S& s, const U& u, const V&) {
    std::string why;
    if (reference(s, u))
        why = "--early-termination applies to the splatters, not to the reference renderer";
    if (s.mode == RenderMode::Dvr && s.order == CompositeOrder::BackToFront)
        why += std::string(why.empty() ? "" : "\n") +
               "--early-termination applies to front-to-back compositing, not to --order btf";
    return why;
}
std::string ignoredWarpTolerance(const S& s, const U& u, const V&) {
    if (u.oneRenderer && s.renderer != RendererKind::Axis)
        return "--warp-tolerance applies to the axis renderer (factorised sheets), not to " +
               renderer(s);
    if (s.mode != RenderMode::Dvr)
        return "--warp-tolerance applies to dvr (factorised sheets), not to " + mode(s);
    if (perspective(s))
        return "--warp-tolerance applies to orthographic views (factorised sheets), not to "
               "perspective ones";
    return {};
}
std::string ignoredLod(const S& s, const U& u, const V&) {
    if (!reference(s, u)) return {};
    return "--lod applies to the splatters, not to the reference renderer";
}
std::string ignoredEwa(const S& s, const U& u, const V&) {
    if (!reference(s, u)) return {};
    return "--ewa applies to the splatters, not to the reference renderer (use --pixel-filter)";
}
std::string ignoredPixelFilter(const S& s, const U& u, const V&) {
    if (!u.oneRenderer || s.renderer == RendererKind::Reference || s.quality.ewa != Ewa::Off)
        return {};
    return "--pixel-filter applies to the reference and to --ewa on|auto, not to " + renderer(s) +
           " with --ewa off";
}
std::string ignoredOrder(const S& s, const U&, const V&) {
    if (s.mode == RenderMode::Dvr) return {};
    return "--order applies to dvr only (" + mode(s) + " does not depend on the compositing order)";
}
std::string ignoredClassify(const S& s, const U&, const V& v) {
    if (!projective(s)) return {};
    return "--classify " + v.text("classify") + " does not apply to " + mode(s) +
           " (no transfer function)";
}
std::string ignoredShade(const S& s, const U&, const V&) {
    if (!projective(s)) return {};
    return "--shade: shading does not apply to " + mode(s) + " (no surfaces or emission to light)";
}
std::string ignoredAmbient(const S& s, const U&, const V& v) { return unshaded("--ambient", s, v); }
std::string ignoredDiffuse(const S& s, const U&, const V& v) { return unshaded("--diffuse", s, v); }
std::string ignoredSpecular(const S& s, const U&, const V& v) {
    return unshaded("--specular", s, v);
}
std::string ignoredShininess(const S& s, const U&, const V& v) {
    return unshaded("--shininess", s, v);
}
std::string ignoredLight(const S& s, const U&, const V& v) { return unshaded("--light", s, v); }
std::string ignoredEdges(const S& s, const U&, const V&) {
    if (s.mode == RenderMode::Dvr) return {};
    return "--edges: edge enhancement scales dvr opacity; not used in " + mode(s);
}
std::string ignoredIsoLevel(const S& s, const U&, const V&) {
    if (s.mode == RenderMode::Iso) return {};
    return "--iso-level applies to iso mode only, not to " + mode(s);
}
std::string ignoredIsoNormalized(const S& s, const U&, const V&) {
    if (s.mode == RenderMode::Iso) return {};
    return "--iso-normalized applies to iso mode only, not to " + mode(s);
}
std::string ignoredFov(const S& s, const U&, const V&) {
    return perspective(s) ? "" : "--fov applies to --projection perspective only";
}
std::string ignoredDistance(const S& s, const U&, const V&) {
    return perspective(s) ? "" : "--distance applies to --projection perspective only";
}
std::string ignoredWindow(const S& s, const U& u, const V&) {
    if (!projective(s))
        return "--window applies to mip and xray (" + mode(s) + " images are written sRGB)";
    if (!eightBit(u.imageExt))
        return "--window applies to 8-bit images (.png); " + u.imageExt +
               " holds the values as computed";
    return {};
}
std::string ignoredBitDepth(const S&, const U& u, const V&) {
    return u.imageExt == ".png" ? "" : "--bit-depth applies to .png images only";
}
std::string ignoredAlpha(const S&, const U& u, const V&) {
    return u.imageExt == ".png" ? "" : "--alpha applies to .png images only";
}

using T = OptionType;
using P = OptionPath;
constexpr OptionScope kVolume = OptionScope::Volume, kScene = OptionScope::Scene,
                      kFrame = OptionScope::Frame, kOutput = OptionScope::Output,
                      kSweep = OptionScope::Sweep;
constexpr const char *kCls = "Classification", *kCam = "Camera", *kRen = "Renderer",
                     *kQ = "Quality", *kOut = "Output", *kVol = "Volume", *kSw = "Sweep";
constexpr OptionSet R = kRenderOptions, I = kImageOptions, W = kSweepOptions, L = kVolumeOptions,
                    K = kStudyOnlyOptions, Rot = kRotateOptions, Vw = kViewOptions,
                    Sl = kSlicesOptions, Mpr = kMprOptions, Cpr = kCprOptions, Iso = kIsoOptions,
                    Rnd = kRenderCommandOptions, Pop = kPoppingOptions, St = kStudyOptions,
                    Bn = kBenchOptions;
constexpr const char *kSeq = "Sequence", *kStudy = "Study", *kBench = "Benchmark", *kSlices = "Slices", *kPlane = "Plane",
                     *kCurve = "Curve", *kSurf = "Surface";

std::vector<OptionSpec> makeTable() {
    return {
        // ---- how to read VOLUME
        {"dims", T::Text, "", "raw data: dimensions XxYxZ, e.g. 256x256x128", kVol, kVolume, L},
        {"type", T::Text, "",
         "raw data: sample type (uint8 int8 uint16 int16 uint32 int32 float32 float64)", kVol,
         kVolume, L},
        {"spacing", T::Text, "", "raw data: spacing X,Y,Z (default 1,1,1)", kVol, kVolume, L},
        {"big-endian", T::Flag, "", "raw data: samples are big-endian", kVol, kVolume, L},
        {"header-bytes", T::Unsigned, "0", "raw data: bytes to skip at the start", kVol, kVolume,
         L},
        {"nan-policy", T::Text, "error",
         "NaN/Inf samples: 'error' refuses the volume, 'zero' replaces them by 0", kVol, kVolume,
         L},
        {"allow-outside-data", T::Flag, "",
         "NRRD/MetaImage: allow data files outside the header's folder (absolute paths, ..)", kVol,
         kVolume, L},
        {"series", T::Text, "",
         "DICOM: the SeriesInstanceUID to load when a folder holds several (`splat info "
         "FOLDER` lists them)",
         kVol, kVolume, L},
        {"time", T::Text, "",
         "time series (4D NIfTI, NRRD with a time axis, a folder of 3D files, OME-Zarr t): "
         "the time step to load, from 0 (default: the first)",
         kVol, kVolume, L},
        {"background-value", T::Text, "",
         "the field's value where nothing is (b; e.g. -1000 for CT in HU): a number, or "
         "'auto' for the median of the outer faces (default: from the file, else auto)",
         kVol, kVolume, L},
        {"grid", T::Text, "",
         "OpenVDB: the grid to load (default: 'density', else the first float or double "
         "grid; `splat info FILE.vdb` lists them)",
         kVol, kVolume, L},
        {"zarr-level", T::Text, "",
         "OME-Zarr: the resolution level, 0 the finest (default: render, rotate and bench the "
         "level the --lod rule picks for the view, docs/input-files.md \"Choosing a level\"; "
         "other commands 0; `splat info` lists them)",
         kVol, kVolume, L},
        {"channel", T::Text, "", "OME-Zarr: the channel of a 4D or 5D image (default 0)", kVol,
         kVolume, L},
        // ---- rendering
        {"mode", T::Text, "dvr", "dvr | mip | xray | iso", kCls, kScene, R},
        {"classify", T::Text, "pre",
         "pre | post: classification before or after reconstruction (dvr, iso)", kCls, kScene, R,
         P::None, ignoredClassify},
        {"tf", T::Text, "gray-ramp",
         "transfer function: preset (ct-bone, ct-soft, mri-head, gray-ramp) or FILE.json "
         "(a scene file may hold it inline as an object)",
         kCls, kScene, R, P::Input},
        {"iso-level", T::Text, "0.5n",
         "iso: level of the density, absolute (120) or a fraction of the volume's "
         "[min, max] ending in n (0.4n)",
         kCls, kFrame, R, P::None, ignoredIsoLevel},
        {"size", T::Text, "512x512", "image size WxH", kCam, kFrame, R},
        {"azimuth", T::Real, "0", "camera azimuth, degrees", kCam, kFrame, R},
        {"elevation", T::Real, "0", "camera elevation, degrees", kCam, kFrame, R},
        {"projection", T::Text, "ortho", "ortho | perspective", kCam, kFrame, R},
        {"pixel-size", T::Real, "0", "world units per pixel (0 = fit the volume)", kCam, kFrame, R},
        {"fov", T::Real, "30", "perspective: vertical field of view, degrees", kCam, kFrame, R,
         P::None, ignoredFov},
        {"distance", T::Real, "0",
         "perspective: eye distance from the volume centre, world units (0 = fit)", kCam, kFrame, R,
         P::None, ignoredDistance},
        {"eye", T::Text, "",
         "free camera: eye position X,Y,Z (world; with --look-at, replaces the orbit)", kCam,
         kFrame, R},
        {"look-at", T::Text, "",
         "free camera: the point X,Y,Z at the image centre (default: the volume centre)", kCam,
         kFrame, R},
        {"up", T::Text, "", "free camera: up vector X,Y,Z (default 0,0,1)", kCam, kFrame, R},
        {"renderer", T::Text, "axis",
         "axis (axis-aligned sheets) | sheet (image-aligned slabs) | reference (ray caster)", kRen,
         kFrame, R},
        {"order", T::Text, "ftb", "dvr: ftb (front-to-back) | btf (back-to-front)", kRen, kFrame, R,
         P::None, ignoredOrder},
        {"kernel", T::Text, "gaussian", "reconstruction kernel: gaussian | bspline", kRen, kScene,
         R},
        {"sigma", T::Real, "0", "Gaussian sigma in voxels (0 = the kernel's default)", kRen, kScene,
         R},
        {"radius", T::Real, "0", "kernel radius in voxels (0 = the kernel's default)", kRen, kScene,
         R},
        {"background", T::Text, "0,0,0,0", "background R,G,B[,A] in [0, 1]", kRen, kFrame, R},
        {"shade", T::Flag, "", "Blinn-Phong shading from the density gradient (dvr, iso)", kRen,
         kScene, R, P::None, ignoredShade},
        {"quality", T::Text, "default",
         "fast | default | exact: sets early-termination, slab, ref-step, ref-tolerance and "
         "the axis-aligned frame design together (fast: about VTK's accuracy; exact: the "
         "converged end); those options given beside it win",
         kQ, kFrame, R},
        {"slab", T::Real, "1", "sheet renderer: slab thickness, voxels", kQ, kFrame, R, P::None,
         ignoredSlab},
        {"early-termination", T::Real, "0.00390625",
         "splatters, front-to-back: stop when opacity >= 1 - EPS (0 = off)", kQ, kFrame, R, P::None,
         ignoredEarlyTermination},
        {"ref-step", T::Real, "0",
         "reference renderer: first step, voxels (0: automatic, dvr 1 for the default kernel, "
         "else 0.25)",
         kQ, kFrame, R, P::None, ignoredRefStep},
        {"ref-tolerance", T::Real, "0.0001", "reference renderer: step refinement tolerance", kQ,
         kFrame, R, P::None, ignoredRefTolerance},
        {"threads", T::Integer, "0", "worker threads (0 = all cores)", kQ, kFrame, R},
        {"tile-size", T::Integer, "32", "splatters: screen tile edge in pixels (8..32)", kQ, kFrame,
         R, P::None, ignoredTileSize},
        {"warp-tolerance", T::Real, "0",
         "axis renderer, orthographic dvr: factorised sheets (2 samples per voxel; 1 with "
         "--quality fast) warped to the screen, with the tiles whose estimated warp error "
         "exceeds this rendered per splat (0..1; 0 = off: per-splat footprints)",
         kQ, kFrame, R, P::None, ignoredWarpTolerance},
        {"lod", T::Text, "0",
         "splatters: level of detail, pixels per voxel below which 2x2x2 voxels are "
         "merged into one splat of twice the size, repeatedly (0..64; 0 = off), or auto: "
         "the coarsest level whose merged voxels stay within the pixel filter (xray), or brick: "
         "that level per brick of 16^3 voxels where its dropped detail and seams stay "
         "small (xray)",
         kQ, kFrame, R, P::None, ignoredLod},
        {"pixel-filter", T::Real, "0",
         "Gaussian pixel filter sigma in pixels (0..4): the reference supersamples and "
         "filters through it (0 = one ray at each pixel centre); the splatters' EWA "
         "low-pass (0 = 0.5)",
         kQ, kFrame, R, P::None, ignoredPixelFilter},
        {"ewa", T::Text, "auto",
         "splatters: EWA resampling, footprints convolved with the pixel filter: off | on | "
         "auto (on in xray while a voxel covers fewer than 1 pixel); default auto",
         kQ, kFrame, R, P::None, ignoredEwa},
        // ---- the classic techniques
        {"iso-normalized", T::Flag, "",
         "--iso-level is a fraction of the volume's [min, max] (same as the n suffix)", kCls,
         kFrame, R, P::None, ignoredIsoNormalized},
        {"edges", T::Text, "",
         "dvr edge enhancement GAIN[,EXPONENT]: opacity x (1 + GAIN ((|grad|/max)^EXP - 1))", kCls,
         kScene, R, P::None, ignoredEdges},
        {"clip-plane", T::TextList, "",
         "cut plane X,Y,Z,NX,NY,NZ (world): removes the side the normal points to; "
         "repeatable",
         kCls, kScene, R},
        {"crop", T::Text, "", "crop box X0,Y0,Z0,X1,Y1,Z1 (world units)", kCls, kScene, R},
        {"label-volume", T::Text, "",
         "segmentation label volume on VOLUME's grid (VOLUME is the intensity)", kCls, kScene, R,
         P::Input},
        {"label-colors", T::Text, "",
         "label colours: FILE.lut (256 x RGB, mricron) or FILE.json; without "
         "--label-volume, VOLUME itself holds the labels",
         kCls, kScene, R, P::Input},
        {"label-names", T::Text, "", "label names: FILE.txt (index name per line)", kCls, kScene, R,
         P::Input},
        {"labels", T::Text, "", "show only these labels, e.g. 37,38", kCls, kScene, R},
        {"label-opacity", T::Real, "1",
         "opacity of the labels per unit distance (tables without their own)", kCls, kScene, R},
        {"tf-rescale", T::Flag, "",
         "stretch the transfer function's first..last control values over the volume's "
         "[min, max] (ParaView's 'rescale to data range')",
         kCls, kScene, R},
        {"ambient", T::Real, "0.35", "shading: ambient coefficient", kRen, kScene, R, P::None,
         ignoredAmbient},
        {"diffuse", T::Real, "0.65", "shading: diffuse coefficient", kRen, kScene, R, P::None,
         ignoredDiffuse},
        {"specular", T::Real, "0.25", "shading: specular coefficient", kRen, kScene, R, P::None,
         ignoredSpecular},
        {"shininess", T::Real, "24", "shading: Blinn-Phong exponent", kRen, kScene, R, P::None,
         ignoredShininess},
        {"light", T::Text, "camera",
         "shading light: camera (headlight) or X,Y,Z world direction towards it", kRen, kScene, R,
         P::None, ignoredLight},
        // ---- the kernel tables' resolutions, swept by a study only
        {"footprint-res", T::Integer, "4096", "footprint table entries over r^2 (16..1048576)", kQ,
         kScene, K},
        {"slab-radial-res", T::Integer, "128", "slab-section table: intervals in r^2 (4..65536)",
         kQ, kScene, K},
        {"slab-depth-res", T::Integer, "1024", "slab-section table: intervals in depth (4..65536)",
         kQ, kScene, K},
        {"poly-tol", T::Real, "1e-06",
         "footprint as a piecewise polynomial when it matches the table to this fraction of "
         "the peak (0: always the table)",
         kQ, kScene, K},
        // ---- the written image
        {"bit-depth", T::Integer, "8", "PNG bits per channel: 8 or 16", kOut, kOutput, I, P::None,
         ignoredBitDepth},
        {"alpha", T::Flag, "", "PNG with alpha (transparent background)", kOut, kOutput, I, P::None,
         ignoredAlpha},
        {"window", T::Text, "",
         "mip/xray 8-bit output: display window LOW,HIGH (default: the data range, 0 included)",
         kOut, kOutput, I, P::None, ignoredWindow},
        // ---- popping's sweep
        {"from", T::Real, "40", "first angle of the sweep, degrees", kSw, kSweep, W},
        {"to", T::Real, "50", "last angle of the sweep (inclusive), degrees", kSw, kSweep, W},
        {"step", T::Real, "0.5", "angle step, degrees", kSw, kSweep, W},
        {"sweep", T::Text, "azimuth", "the angle swept: azimuth or elevation", kSw, kSweep, W},
        {"path", T::Text, "",
         "analyse a camera path instead of a sweep: JSON {\"keys\": [...]} as for rotate, "
         "interpolated over --frames views",
         kSw, kSweep, W, P::Input},
        {"frames", T::Integer, "21", "views of --path (at least 3)", kSw, kSweep, W},
        {"renderers", T::Text, "axis,sheet,reference",
         "renderers to compare (reference: ground truth)", kSw, kSweep, W},
        {"refine", T::Integer, "10", "bisection levels around each event (0: none)", kSw, kSweep,
         W},
        {"threshold-k", T::Real, "5", "event threshold: median + K * MAD of the signal", kSw,
         kSweep, W},
        {"threshold-floor", T::Real, "2", "... and at least FLOOR * median", kSw, kSweep, W},
        {"ppd", T::Real, "67", "LDR-FLIP pixels per degree", kSw, kSweep, W},
        {"no-flip", T::Flag, "", "skip the perceptual (LDR-FLIP) columns", kSw, kSweep, W},
        {"no-warp-flip", T::Flag, "",
         "skip StopThePop's temporal FLIP_1 and FLIP_7 (frames warped with the exact flow of "
         "the cameras and the reference's depth)",
         kSw, kSweep, W},
        {"truth", T::Text, "auto",
         "the reference the splatters are judged against: point (one ray per pixel "
         "centre) | filtered (through the pixel filter, --pixel-filter or 0.5) | auto "
         "(filtered where the splatters' frames are: EWA on, e.g. xray below a pixel per "
         "voxel); default auto",
         kSw, kSweep, W},
        // ---- rotate: the sequence of frames and where they go
        {"frames", T::Integer, "36", "number of frames", kSeq, kSweep, Rot},
        {"from", T::Real, "0", "first angle, degrees", kSeq, kSweep, Rot},
        {"to", T::Real, "360",
         "last angle, degrees (inclusive: the last frame is at --to). Default: a full "
         "turn that loops without repeating a view, from + 360 (frames - 1) / frames",
         kSeq, kSweep, Rot},
        {"sweep", T::Text, "azimuth", "the angle turned: azimuth or elevation", kSeq, kSweep, Rot},
        {"path", T::Text, "",
         "camera path JSON {\"keys\": [{\"azimuth\", \"elevation\", \"distance\", "
         "\"pixel_size\"}, ...]}, interpolated over --frames (instead of --sweep)",
         kSeq, kSweep, Rot, P::Input},
        {"time-steps", T::Text, "",
         "time series: one frame per time step A..B (inclusive, e.g. 0:19; sets --frames); "
         "the camera stays unless --from/--to or --path turn it over the sequence",
         kSeq, kSweep, Rot},
        {"parallel-frames", T::Integer, "0",
         "frames rendered at once, one thread each (0: automatic)", kSeq, kSweep, Rot},
        {"bricks", T::Integer, "0",
         "sort-last: cut the volume into K bricks, loaded and built once, every frame rendered "
         "by them and composited (0: off; under mpirun chosen from --rank-memory when the "
         "volume does not fit one process)",
         kSeq, kScene, Rot},
        {"rank-memory", T::Real, "0",
         "bricks: memory per process in MiB (default under mpirun: 80% of the physical memory "
         "/ processes on the node); frames in parallel when the volume fits",
         kSeq, kScene, Rot},
        {"brick-composite", T::Text, "exact",
         "bricks of the image-aligned splatter: exact (slab sheets summed across bricks: the "
         "same as one process) or fast (partial images, approximate at brick faces)",
         kSeq, kScene, Rot},
        {"compositor", T::Text, "direct",
         "bricks under mpirun: direct (sparse direct-send, the default) | icet (IceT radix-k, "
         "when built with it) | auto (icet when built with it, else direct)",
         kSeq, kScene, Rot},
        {"output", T::Text, "", "output folder for the frames (created)", kOut, kOutput, Rot,
         P::Output, nullptr, "o"},
        {"name", T::Text, "frame_%04d", "frame file name pattern (printf %d of the frame index)",
         kOut, kOutput, Rot},
        {"format", T::Text, "png", "frame format: png, exr or tif", kOut, kOutput, Rot},
        {"resume", T::Flag, "", "render only the frames missing from the folder", kOut, kOutput,
         Rot},
        {"overwrite", T::Flag, "", "replace the frames the folder holds", kOut, kOutput, Rot},
        {"gif", T::Text, "", "also write an animated GIF", kOut, kOutput, Rot, P::Output},
        {"contact-sheet", T::Text, "", "also write a contact sheet (all frames, tiled)", kOut,
         kOutput, Rot, P::Output},
        {"mp4", T::Text, "", "also write an MP4 video (needs the ffmpeg program; png frames)",
         kOut, kOutput, Rot, P::Output},
        {"fps", T::Integer, "12", "GIF and MP4 frames per second (1..100)", kOut, kOutput, Rot},
        {"quiet", T::Flag, "", "no progress output", kOut, kOutput, Rot, P::None, nullptr, "q"},
        // ---- the view commands (slices, mpr, cpr): the reconstruction and the display window
        {"kernel", T::Text, "gaussian", "reconstruction kernel: gaussian | bspline", kRen, kScene,
         Vw},
        {"sigma", T::Real, "0", "Gaussian sigma in voxels (0 = default)", kRen, kScene, Vw},
        {"radius", T::Real, "0", "kernel radius in voxels (0 = default)", kRen, kScene, Vw},
        {"threads", T::Integer, "0", "worker threads (0 = all cores)", kRen, kFrame, Vw},
        {"window", T::Text, "", "display window LO,HI (data units)", kOut, kOutput, Vw},
        {"window-preset", T::Text, "",
         "display window: full (min..max, default), ct-brain (L40 W80), ct-soft (L50 W400), "
         "ct-bone (L500 W2000), ct-lung (L-600 W1500)",
         kOut, kOutput, Vw},
        {"scale-bar", T::Real, "0", "draw a scale bar of this many world units (mm)", kOut, kOutput,
         Vw},
        {"bit-depth", T::Integer, "8", "PNG bits per channel: 8 or 16", kOut, kOutput, Vw},
        // ---- slices
        {"axis", T::Text, "z", "x | y | z", kSlices, kFrame, Sl},
        {"every", T::Integer, "1", "every Nth slice", kSlices, kFrame, Sl},
        {"columns", T::Integer, "0", "mosaic columns (0 = square)", kOut, kOutput, Sl},
        {"format", T::Text, "png", "png | exr | tif", kOut, kOutput, Sl},
        {"output", T::Text, "", "output folder (created)", kOut, kOutput, Sl, P::Output, nullptr,
         "o"},
        // ---- mpr
        {"plane", T::Text, "", "plane POINT,NORMAL: X,Y,Z,NX,NY,NZ (world)", kPlane, kFrame, Mpr},
        {"up", T::Text, "auto", "image up direction X,Y,Z (auto: +z, or +y for axial planes)",
         kPlane, kFrame, Mpr},
        {"size", T::Text, "256x256", "image size WxH", kPlane, kFrame, Mpr},
        {"pixel-size", T::Real, "0", "world units per pixel (0 = smallest spacing)", kPlane, kFrame,
         Mpr},
        {"output", T::Text, "", "output image (.png windowed, .exr/.tif values)", kOut, kOutput,
         Mpr, P::Output, nullptr, "o"},
        // ---- cpr
        {"curve", T::Text, "", "curve FILE.json {\"points\": [[x,y,z], ...]}", kCurve, kFrame, Cpr,
         P::Input},
        {"lateral", T::Text, "", "lateral direction X,Y,Z (default 0,0,1)", kCurve, kFrame, Cpr},
        {"width", T::Integer, "0", "image width, pixels (0: the curve file's, or 128)", kCurve,
         kFrame, Cpr},
        {"pixel-size", T::Real, "0", "world units per pixel (0: the curve file's, or the spacing)",
         kCurve, kFrame, Cpr},
        {"output", T::Text, "", "output image", kOut, kOutput, Cpr, P::Output, nullptr, "o"},
        // ---- iso: the surface as a mesh
        {"level", T::Real, "", "the level L of the surface f = L (data units)", kSurf, kScene, Iso},
        {"kernel", T::Text, "gaussian", "reconstruction kernel (as for render)", kSurf, kScene,
         Iso},
        {"sigma", T::Real, "0", "kernel sigma, voxels (0 = the kernel's default)", kSurf, kScene,
         Iso},
        {"radius", T::Real, "0", "kernel radius, voxels (0 = the kernel's default)", kSurf, kScene,
         Iso},
        {"threads", T::Integer, "0", "threads (0 = all cores)", kSurf, kFrame, Iso},
        {"output", T::Text, "", "mesh file: .ply (binary), .obj or .stl (binary)", kOut, kOutput,
         Iso, P::Output, nullptr, "o"},
        // ---- render: the image and the sort-last bricks
        {"output", T::Text, "",
         "output image: .png (8-bit display), .exr or .tif (float, values as computed)", kOut,
         kOutput, Rnd, P::Output, nullptr, "o"},
        {"bricks", T::Integer, "0",
         "sort-last: cut the volume into K bricks, each loaded alone, rendered and composited "
         "(0: off; under mpirun chosen from --rank-memory)",
         kOut, kScene, Rnd},
        {"rank-memory", T::Real, "0",
         "bricks: memory per process in MiB; the fewest bricks, a multiple of the processes, "
         "whose estimate fits it (default under mpirun: 80% of the physical memory / processes "
         "on the node)",
         kOut, kScene, Rnd},
        {"brick-composite", T::Text, "exact",
         "bricks of --renderer sheet: exact (every slab's sheets summed across bricks, the "
         "one-process image; exchanges sheets) | fast (partial images, a seam of a few percent)",
         kOut, kScene, Rnd},
        {"compositor", T::Text, "direct",
         "bricks under mpirun: how the ranks composite the partial images: direct (sparse "
         "direct-send, the default) | icet (IceT radix-k, when built with it) | auto (icet when "
         "built with it, else direct)",
         kOut, kScene, Rnd},
        // ---- popping: the report and the bricks
        {"report", T::Text, "", "report folder (report.html, metrics.csv, summary.json)", kOut,
         kOutput, Pop, P::Output},
        {"resume", T::Flag, "",
         "finish an interrupted run: reuse the frames it left in REPORT/.frames", kOut, kOutput,
         Pop},
        {"quiet", T::Flag, "", "no progress output", kOut, kOutput, Pop, P::None, nullptr, "q"},
        {"bricks", T::Integer, "0",
         "sort-last: cut the volume into K bricks, loaded and built once, every frame of the "
         "analysis rendered by them and composited (0: off; under mpirun chosen from "
         "--rank-memory when the volume does not fit one process)",
         kOut, kScene, Pop},
        {"rank-memory", T::Real, "0",
         "bricks: memory per process in MiB (default under mpirun: 80% of the physical memory "
         "/ processes on the node); frames in parallel when the volume fits",
         kOut, kScene, Pop},
        {"brick-composite", T::Text, "exact",
         "bricks of the image-aligned splatter: exact (slab sheets summed across bricks: the "
         "same as one process) or fast (partial images, approximate at brick faces)",
         kOut, kScene, Pop},
        {"compositor", T::Text, "direct",
         "bricks under mpirun: direct (sparse direct-send, the default) | icet (IceT radix-k, "
         "when built with it) | auto (icet when built with it, else direct)",
         kOut, kScene, Pop},
        // ---- study: the sweep, its timing and its ground truth
        {"sweep", T::TextList, "",
         "KNOB=V1,V2,... (repeatable): renderer, quality, slab, early-termination, size, order, "
         "classify, kernel, sigma, radius, footprint-res, slab-radial-res, slab-depth-res, "
         "poly-tol, lod, ewa, pixel-filter",
         kStudy, kSweep, St},
        {"repeats", T::Integer, "5", "timed frames per setting and view", kStudy, kSweep, St},
        {"warmup", T::Integer, "1", "untimed frames before them", kStudy, kSweep, St},
        {"views", T::Text, "", "views AZ[:EL],... (default: the camera options)", kStudy, kSweep,
         St},
        {"truth-step", T::Real, "0.125", "reference ray caster step for the ground truth", kStudy,
         kSweep, St},
        {"truth-tolerance", T::Real, "1e-05", "... and its refinement tolerance", kStudy, kSweep,
         St},
        {"truth", T::Text, "auto",
         "the ground truth each setting is judged against: point (one ray per pixel centre) | "
         "filtered (through the pixel filter, pixel-filter or 0.5) | auto (filtered where the "
         "setting's frames are: EWA on, e.g. xray below a pixel per voxel, or a pixel filter); "
         "default auto",
         kStudy, kSweep, St},
        {"ppd", T::Real, "67", "LDR-FLIP pixels per degree", kStudy, kSweep, St},
        {"no-presets", T::Flag, "",
         "do not measure the three --quality presets beside the sweep (by default they are "
         "points of their own, marked on the plot)",
         kStudy, kSweep, St},
        {"convergence", T::Flag, "",
         "also fit the observed convergence orders (slab, reference step, pixel size)", kStudy,
         kSweep, St},
        {"report", T::Text, "",
         "report folder (study.csv, study.json, pareto.svg, pareto.png; references cached there)",
         kOut, kOutput, St, P::Output},
        {"resume", T::Flag, "",
         "finish an interrupted run: keep the points it measured (REPORT/.points)", kOut, kOutput,
         St},
        {"quiet", T::Flag, "", "no progress output", kOut, kOutput, St, P::None, nullptr, "q"},
        // ---- bench
        {"repeats", T::Integer, "5", "timed frames per configuration", kBench, kSweep, Bn},
        {"thread-list", T::Text, "1,2", "thread counts to time, e.g. 1,2", kBench, kSweep, Bn},
        {"json", T::Text, "", "write the results as JSON", kOut, kOutput, Bn, P::Output},
    };
}

}  // namespace

const std::vector<OptionSpec>& optionTable() {
    static const std::vector<OptionSpec> table = makeTable();
    return table;
}

std::vector<const OptionSpec*> optionsOf(unsigned sets) {
    std::vector<const OptionSpec*> out;
    for (const OptionSpec& o : optionTable())
        if (sets & o.set) out.push_back(&o);
    return out;
}

const OptionSpec* findOption(std::string_view name, unsigned sets) {
    for (const OptionSpec& o : optionTable())
        if (o.name == name && (sets & o.set)) return &o;
    return nullptr;
}

const OptionSpec* findOption(std::string_view name) { return findOption(name, kSharedOptions); }

const std::vector<std::string_view>& studyKnobs() {
    static const std::vector<std::string_view> knobs = {"renderer",
                                                        "quality",
                                                        "slab",
                                                        "early-termination",
                                                        "warp-tolerance",
                                                        "size",
                                                        "order",
                                                        "classify",
                                                        "kernel",
                                                        "sigma",
                                                        "radius",
                                                        "footprint-res",
                                                        "slab-radial-res",
                                                        "slab-depth-res",
                                                        "poly-tol",
                                                        "lod",
                                                        "ewa",
                                                        "pixel-filter"};
    return knobs;
}

const char* typeName(OptionType t) {
    switch (t) {
        case OptionType::Real:
            return "FLOAT";
        case OptionType::Integer:
            return "INT";
        case OptionType::Unsigned:
            return "UINT";
        default:
            return "TEXT";
    }
}

}  // namespace splat
