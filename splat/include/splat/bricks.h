#pragma once
// Sort-last bricked rendering (docs/parallel.md), the parts
// that do not need MPI: the volume is cut into K bricks by a k-d tree (uneven splits for odd
// dimensions and K not a power of 2), each brick loaded with ghost layers as wide as the
// kernel's support; a brick is rendered by the unchanged renderers with the whole volume's
// rays (a free camera) clipped to the box the brick owns, and the partial images are
// composited in visibility order (front first): dvr and iso over, mip max, xray sum.
//
// Exact: every ray is cut into the convex pieces the bricks own, and within its own box a
// brick's field equals the whole volume's (its ghost layers hold every sample whose kernel
// reaches the box). The reference ray caster integrates each piece with the same error
// control, so bricked frames match one-process frames within the reference tolerance (tests:
// test_bricks.cpp); the splatters cut their sheet pixels' paths at the brick faces
// (frame/clip_cut.h) and their seam error is measured there.
#include <functional>
#include <memory>
#include <optional>
#include <glm/glm.hpp>
#include <string>
#include <utility>
#include <vector>

#include "splat/image.h"
#include "splat/settings.h"
#include "splat/volume.h"

namespace splat {

struct Brick {
    glm::ivec3 lo{0}, hi{0};          ///< the samples the brick owns, [lo, hi)
    glm::ivec3 loadLo{0}, loadHi{0};  ///< with the ghost layers, clamped to the volume
    std::size_t loadedSamples() const {
        const glm::ivec3 n = loadHi - loadLo;
        return std::size_t(n.x) * std::size_t(n.y) * std::size_t(n.z);
    }
};

/// The k-d tree of the bricks: node 0 is the root; a leaf holds a brick.
struct BrickLayout {
    glm::ivec3 dims{0};
    int ghost = 0;
    std::vector<Brick> bricks;
    struct Node {
        int axis = -1;  ///< -1: a leaf
        int split = 0;  ///< children own [.., split) and [split, ..) along axis
        int child[2] = {-1, -1};
        int brick = -1;
    };
    std::vector<Node> nodes;
};

/// Cuts `dims` into `count` bricks (1 <= count <= the number of samples): the longest axis
/// of a node is split so that its two children, of floor(k/2) and ceil(k/2) bricks, own
/// samples in that ratio. Ghost layers: `ghost` samples on every inner face.
BrickLayout splitBricks(const glm::ivec3& dims, int count, int ghost);

/// Ghost layers a kernel of support radius `radius` (index units) needs on a grid of
/// `spacing`: every sample whose kernel a sheet pixel of the owned box sees, up to
/// R sqrt 2 + 1/2 samples beyond a face (the axis-aligned sheets hold whole kernels, cut
/// along oblique rays), plus one layer for the central-difference gradients: 5 for R = 2.
int ghostLayers(double radius, const glm::dvec3& spacing);

/// The bricks of `layout` front to back as seen by `camera` of a volume of geometry `whole`
/// (dims, spacing, origin; samples not needed): a k-d tree traversal, near child first.
std::vector<int> visibilityOrder(const BrickLayout& layout, const Volume& whole,
                                 const CameraParams& camera);

/// The geometry of `brick` (its loaded box) in the volume `whole`: dims, spacing, origin,
/// background and source; no samples.
Volume brickGeometry(const Volume& whole, const Brick& brick);

/// The settings that render `brick` as its part of `frame` of the volume `whole`: the whole
/// volume's rays (a free camera with its eye, target, up and pixel size), clipped to the box
/// the brick owns (open where it is the volume's face), a transparent background, no early
/// termination (a ray's opacity is not known within one brick).
RenderSettings brickSettings(const RenderSettings& frame, const Volume& whole, const Brick& brick,
                             const glm::ivec3& dims);

/// Composites the partial images of one frame, front first, as `mode` combines pieces of a
/// ray (dvr, iso: over; mip: max; xray: sum), then lays `background` behind (dvr, iso):
/// blendBackground(compositePieces(frontToBack, mode), mode, background).
Image compositeBricks(const std::vector<const Image*>& frontToBack, RenderMode mode,
                      const glm::vec4& background);

/// The pieces of compositeBricks: the partial images combined front first, no background.
Image compositePieces(const std::vector<const Image*>& frontToBack, RenderMode mode);

/// Lays `background` behind a composited frame (dvr, iso: I += (1 - alpha) background; mip
/// and xray: unchanged), pixel by pixel, so it may be applied to any part of the frame.
void blendBackground(Image& image, RenderMode mode, const glm::vec4& background);

}  // namespace splat

namespace splat {

struct LoadOptions;

/// The geometry of the volume `spec` names (dims, spacing, origin, background and its
/// source, the source's description; no samples). `alone` says whether loadVolumeBrick
/// reads a brick's samples alone: synthetic volumes (only the brick is computed), NIfTI
/// (.nii, .nii.gz), NRRD (raw, gzip, bzip2) and MetaImage files and .raw/.raw.gz (the rows of
/// the brick by byte ranges; a compressed file's stream is decompressed from its start and
/// only the brick's bytes kept). The background value follows loadVolume's rule, from the
/// file's outer faces alone (read by byte ranges: equal to the one-process value);
/// `background` false skips that read (b = 0, for a caller that sets it). Any other volume
/// (DICOM, slice folders, NRRD text/hex, ANALYZE pairs) is loaded whole here and by
/// loadVolumeBrick, which keeps the brick.
Volume volumeGeometry(const std::string& spec, const LoadOptions& options, bool* alone,
                      bool background = true);

/// The samples [lo, hi) of the volume `spec` names, origin at sample lo: bit for bit the
/// crop of loadVolume's volume; a brick beyond the end of a truncated file throws
/// splat::Error naming the file and the bytes missing.
Volume loadVolumeBrick(const std::string& spec, const LoadOptions& options, const glm::ivec3& lo,
                       const glm::ivec3& hi);

/// Whether loadVolumeBrick reads a brick of the volume `spec` names alone (volumeGeometry's
/// `alone`), from its name and header, without reading samples.
bool volumeReadsByBrick(const std::string& spec, const LoadOptions& options);

/// Whether brickHoldsOnlyBackground knows the empty bricks of the volume `spec` names (an
/// OpenVDB file).
bool volumeIsSparse(const std::string& spec);

/// The smallest and largest sample of the volume `spec` names, known without reading its
/// samples: an OpenVDB grid's, from its tree. False (lo, hi unchanged) for other volumes.
bool sparseValueRange(const std::string& spec, const LoadOptions& options, float& lo, float& hi);

/// Whether the samples [lo, hi) of the volume `spec` names all equal its background value b,
/// known without reading them: an OpenVDB file's box that no active voxel or tile of another
/// value meets (from the grid's tree). False for every other volume (not known).
bool brickHoldsOnlyBackground(const std::string& spec, const LoadOptions& options,
                              const glm::ivec3& lo, const glm::ivec3& hi);

}  // namespace splat

namespace splat {

struct BrickStats {
    int bricks = 0;                 ///< in the frame
    int rendered = 0;               ///< by this process
    int empty = 0;                  ///< of those, holding only b: not loaded (emptyBrickImage)
    std::size_t samplesLoaded = 0;  ///< the largest brick this process held, ghost layers included
    std::size_t splats = 0;         ///< splats of the bricks this process rendered
    std::uint64_t bytesExchanged = 0;  ///< sent + received by this process (compositing)
    /// Load the samples, build the bricks' Scenes (classification), render their frames,
    /// composite (this process's part of the collective).
    double loadMs = 0, sceneMs = 0, renderMs = 0, compositeMs = 0;
};

/// The processes that render the bricks of a frame together, and the three things they do
/// together (the seam of the MPI module: splat::mpi implements it over MPI; LocalBrickGroup
/// is one process holding every brick). Process r renders the bricks b with b % size == r.
class BrickGroup {
  public:
    virtual ~BrickGroup() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    /// Every process says whether its part succeeded (`error` empty); when one failed, every
    /// process throws splat::Error with the first failed one's message.
    virtual void agree(const std::string& error) = 0;
    /// The smallest lo and largest hi over the processes.
    virtual void range(float& lo, float& hi) = 0;
    /// Composites the partial images (brick index, image) of all processes in the order
    /// `frontToBack` (compositeBricks) and returns the frame on process 0 (others: empty).
    /// Adds the bytes this process sent and received to `bytes`.
    virtual Image composite(std::vector<std::pair<int, Image>>& partials,
                            const std::vector<int>& frontToBack, int width, int height,
                            RenderMode mode, const glm::vec4& background, std::uint64_t* bytes) = 0;
    /// Every process's stats, on process 0 (rank order; others: empty).
    virtual std::vector<BrickStats> gather(const BrickStats& mine) = 0;
    /// Exact sheets (splat/slab_sheets.h): sums `blocks` and takes the minimum of `rects`
    /// element by element over the processes, and leaves process r its part, the tiles
    /// [tileStart[r], tileStart[r + 1]) (`tileFloats` floats and `tileInts` ints each), at the
    /// front of both arrays. A block whose rectangle is empty (kNoRect) holds zeros and
    /// need not be sent. Adds the bytes this process sent and received to `bytes`.
    virtual void reduceSlabs(std::vector<float>& blocks, std::vector<int>& rects,
                             const std::vector<int>& tileStart, std::size_t tileFloats,
                             std::size_t tileInts, std::uint64_t* bytes) = 0;
    /// The sum of every process's `image` on process 0 (others: empty); their non-zero
    /// pixels are disjoint, so the sum is exact.
    virtual Image sumImages(const Image& image, std::uint64_t* bytes) = 0;
    /// Process 0's `bytes` on every process (the others' size and contents are replaced).
    virtual void broadcast(std::vector<unsigned char>& bytes) = 0;
};

/// One process, every brick: what `splat render --bricks K` does without mpirun (each
/// brick is loaded, rendered and freed in turn, so memory follows the largest brick).
class LocalBrickGroup : public BrickGroup {
  public:
    int rank() const override { return 0; }
    int size() const override { return 1; }
    void agree(const std::string& error) override;
    void range(float&, float&) override {}
    Image composite(std::vector<std::pair<int, Image>>& partials,
                    const std::vector<int>& frontToBack, int width, int height, RenderMode mode,
                    const glm::vec4& background, std::uint64_t* bytes) override;
    std::vector<BrickStats> gather(const BrickStats& mine) override { return {mine}; }
    void reduceSlabs(std::vector<float>&, std::vector<int>&, const std::vector<int>&, std::size_t,
                     std::size_t, std::uint64_t*) override {}
    Image sumImages(const Image& image, std::uint64_t*) override { return image; }
    void broadcast(std::vector<unsigned char>&) override {}
};

/// How the partial results of the image-aligned splatter's bricks are composited (the
/// reference and the axis-aligned splatter composite their partial images exactly either way).
enum class BrickComposite {
    /// Every slab's sheets summed over the bricks before compositing (splat/slab_sheets.h):
    /// the one-process frame to float rounding; exchanges the sheets, not images.
    Exact,
    /// Partial images composited over each other: each brick's slabs are cut at its faces as
    /// if uniform across a slab, a seam of up to a few percent of the peak
    /// (docs/parallel.md "Sort-last bricks").
    Fast,
};

class Scene;

/// The bricks of one volume rendered frame after frame (`splat rotate --bricks`): the
/// constructor loads this process's bricks (`load`: the samples of a brick's loaded box,
/// background as `geometry`'s) and, with `keep`, builds their Scenes once; each render()
/// renders a view of them and the group composites it. Every call is collective over the
/// group. The transfer function and a normalised iso level are resolved against the whole
/// volume's range (the group's) once. Edge enhancement (its scale is the whole volume's
/// largest gradient) and labels are refused. Without `keep`, each render() loads, renders
/// and frees the bricks in turn (memory follows the largest brick: renderBricked).
class BrickedFrames {
  public:
    /// `frame`: the settings of every view but the camera. `composite`: how the
    /// image-aligned splatter's bricks are composited.
    /// `empty` (optional) says which bricks hold only the background value b without
    /// loading them (brickHoldsOnlyBackground): such a brick is neither loaded nor rendered
    /// when a volume of b draws nothing but one constant image in this frame's settings
    /// (emptyBrickImage); that image stands for it, so the frame is unchanged.
    BrickedFrames(const Volume& geometry, std::function<Volume(const Brick&)> load,
                  const RenderSettings& frame, int bricks, BrickGroup& group,
                  BrickComposite composite = BrickComposite::Exact, bool keep = true,
                  std::function<bool(const Brick&)> empty = {});
    ~BrickedFrames();
    BrickedFrames(const BrickedFrames&) = delete;
    BrickedFrames& operator=(const BrickedFrames&) = delete;
    /// The frame seen by `camera` (the constructor's settings otherwise), on process 0
    /// (others: empty).
    Image render(const CameraParams& camera);
    /// The same with `renderer` (popping's renderers): each renderer has its own Scenes of
    /// the bricks (built at its first frame, sharing the bricks' samples). `stats`: this
    /// process's splats, the axis-aligned splatter's sheet axis and sign (the whole frame's:
    /// they follow the view) and the milliseconds.
    Image render(const CameraParams& camera, RendererKind renderer, RenderStats* stats = nullptr);
    /// This process's work so far (construction and every render).
    const BrickStats& stats() const { return st_; }
    /// The settings with the transfer function and iso level resolved (the whole volume's).
    const RenderSettings& settings() const { return s_; }
    const BrickLayout& layout() const { return layout_; }

  private:
    std::shared_ptr<const Scene> scene(int index, const RenderSettings& bs);
    Image renderFrame(const CameraParams& camera, RendererKind renderer, RenderStats& stats);
    bool exact(RendererKind renderer) const {
        return renderer == RendererKind::Sheet && composite_ == BrickComposite::Exact;
    }
    Volume loadBrick(int b);
    Image renderPieces(const CameraParams& camera, const RenderSettings& s, RenderStats& stats);
    Image renderInOrder(const CameraParams& camera, const RenderSettings& s, RenderStats& stats);
    Image renderPiece(std::size_t i, const RenderSettings& s, RenderStats& stats);
    std::optional<Image> emptyImage(const RenderSettings& s) const;

    Volume geometry_;
    std::function<Volume(const Brick&)> load_;
    BrickGroup& group_;
    BrickLayout layout_;
    std::vector<int> mine_;
    std::vector<char> empty_;  ///< mine_'s bricks that hold only b
    std::optional<Image> emptyImage_;  ///< the current frame's image of an empty brick
    RenderSettings s_;
    BrickComposite composite_ = BrickComposite::Exact;
    bool keep_ = true;
    /// mine_'s samples (with `keep` for good, else until their Scene).
    std::vector<std::shared_ptr<const Volume>> volumes_;
    /// mine_'s Scenes for each renderer (keep), by RendererKind.
    std::vector<std::vector<std::shared_ptr<const Scene>>> scenes_;
    BrickStats st_;
};

/// One frame: BrickedFrames(geometry, load, frame, bricks, group, composite, false, empty)
/// rendered once at frame.camera; `stats`: this process's work. Returns the frame on
/// process 0.
Image renderBricked(const Volume& geometry, const std::function<Volume(const Brick&)>& load,
                    const RenderSettings& frame, int bricks, BrickGroup& group,
                    BrickStats* stats = nullptr, BrickComposite composite = BrickComposite::Exact,
                    const std::function<bool(const Brick&)>& empty = {});

/// The partial image of a brick that holds only the background value b, in `brickFrame`
/// (brickSettings' settings, clipping of the brick's faces left out) of the volume `whole`:
/// a volume of b that makes no splat and renders one constant image (a mip sees b, x-ray
/// and an unlit b draw nothing) draws that same image over any box, so that image stands
/// for every empty brick. Empty when b makes splats or draws anything else (pre-classified
/// dvr whose transfer function gives b opacity): then empty bricks are rendered.
std::optional<Image> emptyBrickImage(const Volume& whole, const RenderSettings& brickFrame);

/// renderBricked's exact path of the image-aligned splatter (slab_sheets.h): this process's
/// bricks `mine` of `layout` (`scene` gives brick mine[i]'s Scene built with the settings
/// given, clipping cleared) are all held at once, their sheets summed over the processes one
/// group of slabs at a time.
Image renderBrickedSlabs(
    const Volume& geometry, const BrickLayout& layout, const std::vector<int>& mine,
    const std::function<std::shared_ptr<const Scene>(int, const RenderSettings&)>& scene,
    const RenderSettings& frame, BrickGroup& group, BrickStats& stats);

}  // namespace splat
