#pragma once
// The vocabulary of a render: what to draw (mode, classification, transfer function,
// kernel, shading), how (renderer, compositing order, camera) and the Quality knobs that
// trade speed for accuracy. Every such knob lives in Quality, so that a speed/accuracy
// study can move any of them; defaults are the figures docs/accuracy.md's tables are made with.
#include <cstddef>
#include <functional>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "splat/camera.h"
#include "splat/error.h"
#include "splat/transfer.h"

namespace splat {

/// Progress of a long computation: `done` of `total` units, what is being done. Returning
/// false cancels it cleanly (the call throws splat::Cancelled; nothing is left half-done).
using ProgressFn =
    std::function<bool(std::size_t done, std::size_t total, const std::string& what)>;

/// Thrown when a ProgressFn returned false.
class Cancelled : public Error {
  public:
    Cancelled() : Error("cancelled") {}
};

enum class RendererKind { Axis, Sheet, Reference };
enum class RenderMode { Dvr, Mip, Xray, Iso };
enum class Classification { Pre, Post };
enum class CompositeOrder { FrontToBack, BackToFront };
/// EWA resampling in the splatters (Quality::ewa): off, on, or (auto) on in xray while a
/// voxel covers fewer than Quality::kEwaAutoPixels pixels.
enum class Ewa { Off, On, Auto };
/// The reference an analysis judges the splatters against (popping, study, bench_accuracy;
/// docs/accuracy.md "Aliasing and EWA"): the point-sampled reference (one ray per pixel centre),
/// the pixel-filtered one (Quality::pixelFilter, or Quality::kEwaDefaultSigma), or (auto) the
/// filtered one where the splatters' frames are filtered (EWA on, or a pixel filter given)
/// and the point-sampled one elsewhere.
enum class Truth { Auto, Point, Filtered };

/// Blinn-Phong shading, one model for every renderer and mode (docs/decisions.md "Shading"):
///   c' = c (ambient + diffuse |n.l|) + specular |n.h|^shininess
/// for a colour c and unit normal n (two-sided), l the direction towards the light and h the
/// half vector between l and the direction towards the eye. Pre-classified dvr shades the
/// premultiplied emission (e' = e (ambient + diffuse |n.l|) + specular |n.h|^s rho), post-
/// classified dvr each sample's colour, iso the surface colour. The light is fixed to the
/// camera (headlight: l = h = -view) or given as a world direction towards the light.
struct Shading {
    bool enabled = false;
    float ambient = 0.35f, diffuse = 0.65f, specular = 0.25f, shininess = 24.0f;
    bool headlight = true;              ///< light at the eye; else `light` (world)
    glm::vec3 light{0.0f, 0.0f, 1.0f};  ///< world direction towards the light (normalised)
};

/// Edge enhancement (Levoy's gradient-magnitude opacity): rho' = rho max(0, 1 + gain (m^exponent
/// - 1)) with m = |grad d| / G, G the volume's largest central-difference gradient magnitude.
/// gain 0 is the plain render, gain 1 rho m^exponent.
struct EdgeEnhancement {
    float gain = 0.0f, exponent = 1.0f;
    bool enabled() const { return gain != 0.0f; }
};

/// Clipping in world units of the reconstructed field, in every renderer: the
/// reference clips each ray to the kept region, the splatters cut each sheet pixel's path at
/// it (frame/clip_cut.h), and the voxels whose kernels reach the region are kept, so the cut
/// face shows the reconstruction of all the data exactly where the plane is.
struct ClipPlane {
    glm::dvec3 point{0.0}, normal{0.0, 0.0, 1.0};  ///< keeps (x - point) . normal <= 0
};
/// Segmentation labels (docs/decisions.md "Labels"): a label volume on the scene volume's grid
/// rendered with a colour and opacity per label, never interpolated: each sheet pixel takes
/// the label of the voxel whose kernel weighs most there (nearest-label classification; the
/// reference: the nearest voxel), so only colours of the table appear. With an intensity
/// volume (the scene's volume) its pre-classified emission is composited with the labels.
struct Labels {
    bool enabled = false;
    /// The labels; null: the scene's volume itself holds them (no intensity part).
    std::shared_ptr<const Volume> volume;
    /// Colour and opacity per unit distance, indexed by label (label 0: background).
    std::vector<glm::vec4> table;
    std::vector<std::string> names;
    std::vector<int> selection;  ///< shown labels; empty: all non-zero labels in the table
    /// The table's entry for `label`, or transparent (unselected, unknown, background).
    glm::vec4 shown(int label) const;
    /// From a mricron .lut (256 x RGB, planar bytes) and optional .txt (index name) or a
    /// JSON table {"labels": [{"index": 1, "name": "...", "color": [r, g, b], "opacity": a}]}
    /// (colours in [0, 1]); `opacity` for tables without their own.
    static Labels load(const std::string& colours, const std::string& names, float opacity);
};

struct Clipping {
    std::vector<ClipPlane> planes;
    bool cropBox = false;
    glm::dvec3 boxMin{0.0}, boxMax{0.0};  ///< world, inclusive
    bool enabled() const { return cropBox || !planes.empty(); }
    bool keeps(const glm::dvec3& x) const;
};

/// Level of detail of the splatters (`--lod`, docs/speed-vs-accuracy.md "Level of detail"): one
/// of off, a pixel threshold, auto or brick. The reference ray caster ignores it.
struct LevelOfDetail {
    enum class Kind {
        /// Always the full-resolution splat list.
        Off,
        /// While a voxel of the level in use covers fewer than `pixels` pixels (its largest
        /// spacing over the pixel size; perspective: at the volume's nearest depth), the
        /// splatters use the next level, 2x2x2 voxels merged into one splat of twice the size
        /// (Laur & Hanrahan).
        Pixels,
        /// A level chosen per view from the error it adds (`--lod auto`): in the modes where
        /// it was measured free in accuracy against the pixel-filtered reference
        /// (lodAutoApplies, model/level_of_detail.h), the coarsest level whose merged splats,
        /// low-passed to what the filtered reference sees (the level-0 kernel plus the pixel
        /// filter, less the pyramid's box), still sum to a constant on their grid; a pixel or
        /// more per voxel keeps level 0 (bit-identical to off).
        Auto,
        /// A level per brick and view (`--lod brick`, model/brick_lod.h): in the modes of
        /// Auto, a level per brick of 16^3 voxels, the coarsest the projected voxel size at the
        /// brick allows (lodAutoLevel) whose dropped detail and whose seams with finer
        /// neighbours stay within a tolerance of the field, each level splatted as Auto splats
        /// it; the frame sums a frame per level (X-ray).
        Brick,
    };
    Kind kind = Kind::Off;
    /// The threshold of Pixels, pixels per voxel, 0..64 (0 for the other kinds).
    double pixels = 0;

    /// Pixels with threshold `pixels` (0: Off).
    static LevelOfDetail threshold(double pixels) {
        return {pixels > 0 ? Kind::Pixels : Kind::Off, pixels};
    }
    static LevelOfDetail automatic() { return {Kind::Auto, 0}; }
    static LevelOfDetail perBrick() { return {Kind::Brick, 0}; }
    bool off() const { return kind == Kind::Off; }
    /// Auto or Brick: the merged levels are low-passed to what the filtered reference sees.
    bool filtered() const { return kind == Kind::Auto || kind == Kind::Brick; }
    bool operator==(const LevelOfDetail&) const = default;
};

/// Every knob that trades speed for accuracy.
struct Quality {
    /// Image-aligned slab thickness, voxels (one voxel = the smallest spacing).
    double slab = 1.0;
    /// Front-to-back early termination when opacity >= 1 - epsilon (0 disables).
    double earlyTermination = 1.0 / 256.0;
    /// Footprint table entries over r^2 in [0, R^2] (footprint::FootprintTable).
    int footprintResolution = 4096;
    /// Slab-section table: intervals in r^2 and in depth (footprint::SlabTable).
    int slabRadialResolution = 128, slabDepthResolution = 1024;
    /// The vectorised loops evaluate the footprint as a piecewise polynomial when it
    /// matches the table to this fraction of the peak; 0 always reads the table.
    double polynomialTolerance = 1e-6;
    /// Reference ray caster: first-pass step in voxels, and the per-pixel change at which
    /// step halving stops.
    double referenceStep = 0.25, referenceTolerance = 1e-4;
    /// Screen tile edge, pixels (8..32: early termination tracks a tile in 64 blocks of 4x4 pixels): each tile owns its sheets and compositing.
    int tileSize = 32;
    /// Level of detail of the splatters: off, a pixel threshold, auto or brick.
    LevelOfDetail lod;
    /// Pixel filter, a Gaussian of this standard deviation in pixels truncated at 4 sigma
    /// (docs/accuracy.md "Aliasing and EWA"). Reference ray caster: 0 samples each pixel at its
    /// centre; > 0 supersamples s x s rays per pixel (s = 2, 4, 8, 16) and filters, doubling s
    /// until the filtered image's RMS change, relative to its largest value, is below
    /// pixelFilterTolerance. Splatters: the EWA low-pass (0: kEwaDefaultSigma). 0..4.
    double pixelFilter = 0;
    double pixelFilterTolerance = 2e-4;
    /// EWA resampling in the splatters (Zwicker et al. 2001): each footprint convolved with
    /// the Gaussian pixel filter, energy kept (footprint/ellipse.h, ewaFootprint). Auto: on in
    /// xray while a voxel covers fewer than kEwaAutoPixels pixels (measured to lower the error
    /// against the filtered reference there, and to raise it in dvr): the default, which
    /// leaves every other mode and image size bit-identical to off (docs/accuracy.md "Aliasing and
    /// EWA").
    Ewa ewa = Ewa::Auto;
    /// Axis-aligned splatter, orthographic pre-classified dvr without clipping, labels, EWA or
    /// merged levels: 0 splats every footprint into screen tiles (the default: n = 2 is faster
    /// but loses accuracy at sharp opaque edges, docs/performance.md "Factorised sheets as the
    /// default design: measured, not kept"); n >= 1 uses factorised sheets instead
    /// (splatters/factorised_sheets.h: one footprint stamp per sheet on an intermediate image
    /// of n samples per voxel along the sheet, warped to the screen once). -P (an experiment, any orthographic frame of the axis-aligned splatter):
    /// per-frame footprint stamps at P x P sub-pixel phases instead of the footprint
    /// polynomial per pixel. Other frames ignore it.
    int factorisedSheets = 0;
    /// Factorised sheets with per-splat edge tiles (`--warp-tolerance`): > 0 renders the
    /// frames factorised sheets apply to by factorised sheets (factorisedSheets samples per
    /// voxel, 2 when it is 0), and every tile holding a pixel whose estimated warp error (the
    /// spline through every other intermediate sample against the spline through all, over 7,
    /// in any premultiplied channel) exceeds this by the per-splat frame instead (0: off).
    double warpTolerance = 0;
    /// The EWA low-pass when pixelFilter is 0, pixels (pbrt-v4's Gaussian pixel filter).
    static constexpr double kEwaDefaultSigma = 0.5;
    /// Ewa::Auto turns EWA on while a voxel covers fewer pixels than this (measured: docs/accuracy.md "Aliasing and EWA").
    static constexpr double kEwaAutoPixels = 1.0;
};

struct RenderSettings {
    RendererKind renderer = RendererKind::Axis;
    RenderMode mode = RenderMode::Dvr;
    CompositeOrder order = CompositeOrder::FrontToBack;
    Classification classification = Classification::Pre;
    TransferFunction transfer = TransferFunction::preset("gray-ramp");
    CameraParams camera;
    std::string kernel = "gaussian";           ///< footprint::Kernel::fromName
    double kernelSigma = 0, kernelRadius = 0;  ///< 0: the kernel's defaults
    glm::vec4 background{0.0f};                ///< premultiplied RGBA behind the volume
    double isoLevel = 0.5;                     ///< iso mode: level of f (absolute density)
    bool isoNormalized = false;                ///< isoLevel is a fraction of [min, max]
    Shading shading;                           ///< dvr (pre and post) and iso
    EdgeEnhancement edges;                     ///< dvr (pre and post)
    Clipping clipping;                         ///< every mode and renderer
    Labels labels;                             ///< dvr: segmentation labels
    int threads = 0;                           ///< every stage of a frame; 0: all cores
    Quality quality;
    /// Progress inside one frame: called, serialised, after every screen tile of
    /// a splatter (`what` "tiles"; the streaming path: after every chunk, "chunks") and every
    /// image row of the reference ray caster ("rows"), with a total known up front. Returning
    /// false cancels the frame: the tiles and rows not yet started are skipped and render
    /// throws splat::Cancelled (worst-case latency: the slowest single tile or row in flight).
    ProgressFn progress;
};

/// Counters of one frame.
struct RenderStats {
    double milliseconds = 0;
    std::size_t splats = 0;           ///< splats in the list
    std::size_t voxels = 0;           ///< voxels considered by classification
    std::size_t footprintPixels = 0;  ///< footprint-pixel updates
    std::size_t sheets = 0;           ///< sheets composited (summed over tiles)
    std::size_t culledSplats = 0;     ///< splats skipped by occlusion culling
    double referenceStep = 0;         ///< reference: final step (voxels)
    /// Axis-aligned splatter: the volume axis (0 = i, 1 = j, 2 = k) its sheets were
    /// perpendicular to, and the sign of the ray direction along it (+1: sheets visited
    /// in increasing index order front to back). -1 and 0 for the other renderers.
    int sheetAxis = -1, sheetSign = 0;
    /// Image-aligned splatter: slabs of the frame's slab grid.
    std::size_t slabs = 0;
    /// Stage times, ms: shade, project, order (visiting keys), bin, tiles (cut kernels into
    /// sheets and composite), resolve (background).
    double shadeMs = 0, projectMs = 0, orderMs = 0, binMs = 0, tilesMs = 0;
    /// What the frame modelled: only what the scene needs, visibly.
    bool perspective = false;         ///< the perspective path ran (per-splat footprints)
    std::size_t normals = 0;          ///< splat normals held by the Scene (0: no gradients)
    std::size_t pathScalePixels = 0;  ///< per-pixel perspective path scales allocated
    /// Pixels handed to the exact path (the reference ray caster of the same model) because
    /// a kernel straddles or lies behind the perspective near plane (eye inside or within
    /// two kernel radii of the volume's kernels), where a local-affine footprint is invalid.
    std::size_t exactPixels = 0;
    /// Factorised sheets with Quality::warpTolerance: pixels taken from the per-splat frame
    /// (edges the warp cannot follow), and the tiles it rendered for them.
    std::size_t warpFixPixels = 0, warpFixTiles = 0;
    /// Why pixels went to the exact path (empty when none did): a splatter's frame with
    /// exactPixels > 0 is the reference's, and comparing it with the reference says nothing.
    /// The command line prints it as a warning; popping and study reports mark such frames.
    std::string exactReason;
    /// Level of detail the splatters used (Quality::lod): 0 the full-resolution list, L the
    /// list of 2^L x 2^L x 2^L voxels merged per splat, holding lodSplats splats (= splats at
    /// level 0; 0 for frames of the reference ray caster).
    /// With `--lod auto` a frame mixes levels, a level per brick (LevelOfDetail::Kind::Auto): lodLevel
    /// is then the coarsest level splatted, lodSplats the splats splatted over all levels and
    /// lodLevelSplats[L] those of level L (empty for frames of the reference ray caster).
    int lodLevel = 0;
    std::size_t lodSplats = 0;
    std::vector<std::size_t> lodLevelSplats;
    /// Reference with a pixel filter (Quality::pixelFilter): rays per pixel along each axis
    /// of the last pass, and the RMS change of the filtered image from the pass before,
    /// relative to its largest value.
    int pixelSamples = 0;
    double pixelFilterChange = 0;
    /// Splatters: the EWA low-pass sigma the footprints were convolved with (0: off).
    double ewaSigma = 0;
};

/// The one enum <-> string table: names as used by the command line and scene files.
const char* toString(RendererKind);
const char* toString(RenderMode);
const char* toString(Classification);
const char* toString(CompositeOrder);
const char* toString(Projection);
const char* toString(Ewa);
const char* toString(Truth);
/// Parse a name; throw splat::Error listing the accepted names otherwise.
RendererKind parseRenderer(std::string_view);
RenderMode parseMode(std::string_view);
Classification parseClassification(std::string_view);
CompositeOrder parseOrder(std::string_view);
Projection parseProjection(std::string_view);
Ewa parseEwa(std::string_view);
Truth parseTruth(std::string_view);

}  // namespace splat
