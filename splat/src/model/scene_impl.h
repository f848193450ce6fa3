#pragma once
// What the frame stages see of a Scene (splat/scene.h): the view-independent state, the
// parts made lazily when a renderer first needs them, and a pool of per-frame workspaces.
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "footprint/footprint_poly.h"
#include "footprint/footprint_table.h"
#include "footprint/kernel.h"
#include "footprint/slab_table.h"
#include "frame/chunk_binning.h"
#include "frame/projection.h"
#include "frame/tile_binning.h"
#include "frame/transfer_table.h"
#include "model/brick_lod.h"
#include "splat/scene.h"

namespace splat {

class ReferenceField;

/// Per-frame arrays, reused by the frames of a sequence so that they do not allocate (and
/// fault in) fresh memory every frame. One frame uses one workspace at a time.
struct FrameWorkspace {
    ProjectedSplats proj;
    TileBins bins;
    std::vector<std::uint32_t> order;      ///< visiting order of the splats
    std::vector<std::uint32_t> key, span;  ///< per splat: sheets (SheetRecord), when binned
    std::vector<float> r, g, b;            ///< shaded emission of this view
    SheetChunks chunks;                    ///< streaming splatters: visiting order
    ChunkBins chunkBins;                   ///< streaming splatters: one chunk's lists
};

struct Scene::Impl {
    std::shared_ptr<const Volume> volume;
    RenderSettings settings;  ///< transfer function resolved
    RenderSettings given;     ///< as the Scene was constructed (frames are checked against it)
    footprint::Kernel kernel;
    SplatList splats;  ///< (k, j, i) order
    TransferTable transfer;
    footprint::FootprintTable table;
    std::optional<footprint::FootprintPoly> poly;  ///< when within polynomialTolerance

    Impl(std::shared_ptr<const Volume> v, const RenderSettings& s);
    /// The next level of detail of `fine` (model/level_of_detail.h): its grid (no samples)
    /// and merged splats, with fine's settings, kernel and tables.
    struct Coarser {};
    Impl(const Impl& fine, Coarser);

    /// Level of detail of this list: 0 for the scene's own, L for 2^L x 2^L x 2^L voxels
    /// merged per splat.
    int level = 0;
    /// The next level (2x the spacing), made on first use and kept; null when this level's
    /// grid is one voxel along every axis. The splatters render a level like any scene.
    const Impl* coarser() const;

    /// `--lod auto` per brick (model/brick_lod.h): a part of a level, `splats` (a subset of
    /// that level's list), with its grid, settings, kernel and tables.
    struct Part {};
    Impl(const Impl& level, SplatList splats, Part);
    /// The pyramid's per-brick detail (brickDetail over levels 0 .. kLodBrickMaxLevel), made
    /// on first use; call on level 0.
    const BrickDetail& brickDetail() const;
    /// One part per level in use for the bricks' `levels` (brickLevels), finest first: the
    /// level itself where every brick holding its splats took it, else splatsOfBricks. The
    /// last frame's parts are kept and reused while the levels are the same. Call on level 0.
    std::vector<std::shared_ptr<const Impl>> lodParts(const std::vector<std::uint8_t>& levels) const;

    float minValue = 0, maxValue = 0;  ///< of the volume (normalized iso levels)
    /// Labels: colour and extinction (a) per label as shown, and the shown label of every
    /// voxel (the reference's nearest-voxel lookup); empty without labels.
    std::vector<glm::vec4> labelTable;
    std::vector<std::uint16_t> labelGrid;

    /// Pre-classified shading: the view's emission is shaded per splat (stage "shade").
    bool shaded() const {
        return settings.shading.enabled && settings.mode == RenderMode::Dvr &&
               settings.classification == Classification::Pre;
    }
    /// The sheets carry gradient channels: post-classified dvr with shading or edges, and
    /// iso (always shaded). Computed only then (DESIGN: gradients only when asked for).
    bool needsGradients() const {
        if (settings.mode == RenderMode::Iso) return true;
        return settings.mode == RenderMode::Dvr &&
               settings.classification == Classification::Post &&
               (settings.shading.enabled || settings.edges.enabled());
    }
    /// Splats ordered (stably) by slice index along `axis`, made on first use: `order`
    /// lists the splat indices (empty for axis 2: the list is in (k, j, i) order already, so
    /// the order is the identity and is not stored) and slice q holds positions
    /// [start[q], start[q + 1]) of the order.
    struct SliceOrder {
        std::vector<std::uint32_t> order;
        std::vector<std::uint32_t> start;
        std::uint32_t at(std::size_t n) const {
            return order.empty() ? std::uint32_t(n) : order[n];
        }
        const std::vector<std::uint32_t>* base() const { return order.empty() ? nullptr : &order; }
    };
    const SliceOrder& sliceOrder(int axis) const;
    /// The list cut into cells of kCellWidth voxels along i within each row (k, j): cell
    /// (k * dims.y + j) * cellsX + c holds the splats of row (k, j) with i in
    /// [c kCellWidth, (c + 1) kCellWidth), at list positions [start[cell], start[cell + 1])
    /// (the list is in (k, j, i) order, so cells are consecutive). Made on first use: the
    /// axis-aligned splatter reads any slab of kCellWidth slices along any axis from it in
    /// runs of consecutive splats, without a sorted copy of the list per axis.
    static constexpr int kCellWidth = 8;
    int cellsX() const { return (volume->dims.x + kCellWidth - 1) / kCellWidth; }
    const std::vector<std::uint32_t>& cellStarts() const;
    /// Splats per brick of kCellWidth^3 voxels, brick (bi, bj, bk) at
    /// (bk * bricks.y + bj) * bricks.x + bi: a slab of the axis-aligned splatter along any axis
    /// is one layer of these bricks (made with cellStarts()).
    const std::vector<std::uint32_t>& brickCounts() const;
    glm::ivec3 bricks() const { return (volume->dims + (kCellWidth - 1)) / kCellWidth; }
    /// The slab-section table of the image-aligned splatter, made on first use.
    const footprint::SlabTable& slabTable() const;
    /// The dense field of the reference ray caster (unshaded scenes), made on first use.
    const ReferenceField& referenceField() const;

    std::unique_ptr<FrameWorkspace> acquireWorkspace() const;
    void releaseWorkspace(std::unique_ptr<FrameWorkspace> w) const;

  private:
    mutable std::mutex lazyMutex_, poolMutex_;
    mutable std::unique_ptr<SliceOrder> sliceOrder_[3];
    mutable std::unique_ptr<std::vector<std::uint32_t>> cellStarts_, brickCounts_;
    mutable std::unique_ptr<footprint::SlabTable> slabTable_;
    mutable std::shared_ptr<const ReferenceField> field_;
    mutable std::vector<std::unique_ptr<FrameWorkspace>> pool_;
    mutable std::unique_ptr<Impl> coarser_;
    mutable std::mutex lodMutex_;
    mutable std::unique_ptr<BrickDetail> brickDetail_;
    mutable std::vector<std::uint8_t> lodLevels_;
    mutable std::vector<std::shared_ptr<const Impl>> lodParts_;
};

/// A workspace taken from a Scene's pool for the duration of one frame.
class WorkspaceLease {
  public:
    explicit WorkspaceLease(const Scene::Impl& scene)
        : scene_(scene), work_(scene.acquireWorkspace()) {}
    ~WorkspaceLease() { scene_.releaseWorkspace(std::move(work_)); }
    WorkspaceLease(const WorkspaceLease&) = delete;
    WorkspaceLease& operator=(const WorkspaceLease&) = delete;
    FrameWorkspace& operator*() const { return *work_; }
    FrameWorkspace* operator->() const { return work_.get(); }

  private:
    const Scene::Impl& scene_;
    std::unique_ptr<FrameWorkspace> work_;
};

/// Stable counting sort: the elements of `base` (or 0 .. key.size() - 1 when `base` is
/// null) ordered by key[element], keys in [0, keys).
void orderByKey(const std::vector<std::uint32_t>& key, std::uint32_t keys,
                const std::vector<std::uint32_t>* base, std::vector<std::uint32_t>& order);

/// Runs `f` on at most `threads` threads (0: all cores): every parallel stage inside
/// runs in that arena.
void runOnThreads(int threads, const std::function<void()>& f);

}  // namespace splat
