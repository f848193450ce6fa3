#pragma once
// Where the frames of a sequence are rendered (docs/parallel.md). renderSequence renders
// them in this process unless a FrameFarm is installed: then it hands the farm the list of views,
// and the farm renders them wherever it likes (the MPI module splat/mpi: on other processes that
// hold the same Scene) and gives them back in view order. The core never calls MPI; the farm is the
// seam. Pixels do not depend on the process or the thread count that rendered them, so a farm
// changes no output.
#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "splat/camera.h"
#include "splat/sequence.h"
#include "splat/settings.h"

namespace splat {

/// One view of a sequence, rendered by every renderer of the sequence.
struct FrameJob {
    std::size_t view = 0;
    CameraParams camera;
};

/// Renders `job` with each of `renderers` from `scene` (the Scene's settings with the job's
/// camera and each renderer), as renderSequence does in one process.
SequenceFrame renderFrameJob(const Scene& scene, const std::vector<RendererKind>& renderers,
                             const FrameJob& job);

class FrameFarm {
  public:
    virtual ~FrameFarm() = default;
    /// Renders every job of `jobs` with `renderers` and hands each frame to `sink`, in jobs
    /// order, on the calling thread. `local` renders one job in this process (a farm may
    /// give this process a share of the work). A job that fails anywhere throws
    /// splat::Error here (what failed, and where); exceptions from `sink` propagate, and the
    /// farm is ready for the next call in either case.
    virtual void render(const std::vector<RendererKind>& renderers,
                        const std::vector<FrameJob>& jobs,
                        const std::function<SequenceFrame(const FrameJob&)>& local,
                        const std::function<void(SequenceFrame&&)>& sink) = 0;
};

/// Installs the process's farm (null: render here); renderSequence uses it from then on.
void installFrameFarm(std::shared_ptr<FrameFarm> farm);
/// The installed farm, or null.
FrameFarm* installedFrameFarm();

}  // namespace splat
