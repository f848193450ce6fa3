#pragma once
// Rendering sequences of views (rotations, sweeps, camera paths) from one Scene: the engine
// shared by `splat rotate` and the popping analyzer. Frames come back in index order; they
// are rendered several at once (one thread each) where that is faster than one frame on
// every thread, and the images do not depend on which.
#include <functional>
#include <string>
#include <vector>

#include "splat/camera.h"
#include "splat/error.h"
#include "splat/image.h"
#include "splat/scene.h"
#include "splat/settings.h"

namespace splat {

// ProgressFn and Cancelled: splat/settings.h.

/// The views of a sequence.
struct CameraPath {
    std::vector<CameraParams> views;

    enum class Angle { Azimuth, Elevation };
    /// `frames` views turning `angle` evenly from `from` to `to`, both inclusive (the one
    /// end-point convention of docs/decisions.md "Sequences": the last view is `to`; one frame
    /// is `from`). A loop that does not repeat its first view ends one step short of a full
    /// turn: to = from + 360 (frames - 1) / frames (the `splat rotate` default).
    static CameraPath turn(const CameraParams& base, Angle angle, double from, double to,
                           int frames);
    /// A JSON camera path: {"keys": [{"azimuth": 0, "elevation": 10, "distance": 400}, ...]}
    /// (each key's missing fields keep the base camera's), `frames` views interpolated
    /// linearly along the keys by their index (at least 2 keys; `frames` >= 2).
    static CameraPath fromJson(const std::string& path, const CameraParams& base, int frames);
};

struct SequenceOptions {
    /// Frames rendered at once, each on one thread; 0: one per thread for images up to
    /// 256 x 256 pixels and scenes of up to 1M splats, else one frame at a time on
    /// every thread.
    int parallelFrames = 0;
    /// Called (serialised) after every frame with done frames of `total` = views x
    /// renderers, fixed up front; and inside each frame after every tile or row with the
    /// same done and total (`what` names the frame and its tiles/rows), so that returning
    /// false cancels the frame in flight too.
    ProgressFn progress;
    /// Views to leave out (e.g. frames already on disk); null: none.
    std::function<bool(std::size_t view)> skip;
};

/// One view as rendered by each renderer asked for.
struct SequenceFrame {
    std::size_t view = 0;
    std::vector<Image> images;  ///< renderers order
    std::vector<RenderStats> stats;
};

/// Renders every view of `path` with each of `renderers` from `scene`, and hands the
/// frames to `sink` in view order (from the calling thread). Throws splat::Cancelled when
/// progress returns false (frames handed over before stay handed over).
void renderSequence(const Scene& scene, const std::vector<RendererKind>& renderers,
                    const CameraPath& path, const SequenceOptions& options,
                    const std::function<void(SequenceFrame&&)>& sink);

}  // namespace splat
