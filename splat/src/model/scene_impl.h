#pragma once
// What the renderers see of a Scene (splat/scene.h): the model, built once and view
// independent (volume, settings, kernel and footprint tables, classified splat list,
// transfer table, levels of detail), and an opaque slot per renderer for the state it keeps
// per scene (its caches, made on first use), whose types the model does not know.
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "footprint/footprint_poly.h"
#include "footprint/footprint_table.h"
#include "footprint/kernel.h"
#include "model/brick_lod.h"
#include "model/transfer_table.h"
#include "splat/scene.h"

namespace splat {

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
    std::vector<std::shared_ptr<const Impl>> lodParts(
        const std::vector<std::uint8_t>& levels) const;

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
    /// iso (always shaded). Computed only then (docs/design.md: gradients only when asked for).
    bool needsGradients() const {
        if (settings.mode == RenderMode::Iso) return true;
        return settings.mode == RenderMode::Dvr &&
               settings.classification == Classification::Post &&
               (settings.shading.enabled || settings.edges.enabled());
    }
    /// The state renderer `State` keeps for this scene (e.g. visiting orders, tables, a
    /// dense field, per-frame workspaces), made by State(const Impl&) on first use and owned
    /// here; every level and part of the pyramid has its own. State's constructor must be
    /// cheap and must not call state(): it runs under the slot lock, and the state makes its
    /// own parts lazily (guarding them itself: frames may share a Scene across threads).
    template <class State>
    State& state() const {
        std::lock_guard<std::mutex> lock(stateMutex_);
        std::unique_ptr<StateSlot>& slot = states_[&stateKey<State>];
        if (!slot) slot = std::make_unique<Holder<State>>(*this);
        return static_cast<Holder<State>&>(*slot).state;
    }

  private:
    struct StateSlot {
        virtual ~StateSlot() = default;
    };
    template <class State>
    struct Holder final : StateSlot {
        explicit Holder(const Impl& scene) : state(scene) {}
        State state;
    };
    /// One address per State type: the key of its slot.
    template <class State>
    static inline const char stateKey = 0;

    mutable std::mutex lazyMutex_, stateMutex_;
    mutable std::map<const void*, std::unique_ptr<StateSlot>> states_;
    mutable std::unique_ptr<Impl> coarser_;
    mutable std::mutex lodMutex_;
    mutable std::unique_ptr<BrickDetail> brickDetail_;
    mutable std::vector<std::uint8_t> lodLevels_;
    mutable std::vector<std::shared_ptr<const Impl>> lodParts_;
};

/// Throws splat::Error for frame settings no renderer can honour (the Scene checks its own
/// settings with it too).
void validateFrame(const RenderSettings& settings);

/// Runs `f` on at most `threads` threads (0: all cores): every parallel stage inside
/// runs in that arena.
void runOnThreads(int threads, const std::function<void()>& f);

}  // namespace splat
