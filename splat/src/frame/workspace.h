#pragma once
// The splatters' per-frame arrays, pooled per Scene (Scene::Impl::state) so that the frames
// of a sequence reuse them instead of allocating (and faulting in) fresh memory every frame.
#include <memory>
#include <mutex>
#include <vector>

#include "frame/chunk_binning.h"
#include "frame/projection.h"
#include "frame/tile_binning.h"
#include "model/scene_impl.h"

namespace splat {

/// Per-frame arrays. One frame uses one workspace at a time.
struct FrameWorkspace {
    ProjectedSplats proj;
    TileBins bins;
    std::vector<std::uint32_t> order;      ///< visiting order of the splats
    std::vector<std::uint32_t> key, span;  ///< per splat: sheets (SheetRecord), when binned
    std::vector<float> r, g, b;            ///< shaded emission of this view
    SheetChunks chunks;                    ///< streaming splatters: visiting order
    ChunkBins chunkBins;                   ///< streaming splatters: one chunk's lists
};

/// The workspaces of one Scene (a Scene::Impl state): frames running at once each take one.
class WorkspacePool {
  public:
    explicit WorkspacePool(const Scene::Impl&) {}
    std::unique_ptr<FrameWorkspace> acquire() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (pool_.empty()) return std::make_unique<FrameWorkspace>();
        std::unique_ptr<FrameWorkspace> w = std::move(pool_.back());
        pool_.pop_back();
        return w;
    }
    void release(std::unique_ptr<FrameWorkspace> w) {
        std::lock_guard<std::mutex> lock(mutex_);
        pool_.push_back(std::move(w));
    }

  private:
    std::mutex mutex_;
    std::vector<std::unique_ptr<FrameWorkspace>> pool_;
};

/// A workspace taken from a Scene's pool for the duration of one frame.
class WorkspaceLease {
  public:
    explicit WorkspaceLease(const Scene::Impl& scene)
        : pool_(scene.state<WorkspacePool>()), work_(pool_.acquire()) {}
    ~WorkspaceLease() { pool_.release(std::move(work_)); }
    WorkspaceLease(const WorkspaceLease&) = delete;
    WorkspaceLease& operator=(const WorkspaceLease&) = delete;
    FrameWorkspace& operator*() const { return *work_; }
    FrameWorkspace* operator->() const { return work_.get(); }

  private:
    WorkspacePool& pool_;
    std::unique_ptr<FrameWorkspace> work_;
};

}  // namespace splat
