#pragma once
// Bricked frames on request (`splat popping` in bricks under mpirun, docs/parallel.md): the
// analysis decides which frames it needs as it goes (the refinement bisects towards an event), so
// it runs on rank 0 alone and asks the group for each frame: rank 0 broadcasts the view and the
// renderer, every rank renders its bricks of it (BrickedFrames::render, collective) and the group
// composites the frame onto rank 0. The other ranks serve these requests until rank 0 ends them.
// The core library stays free of MPI: the requests travel through BrickGroup::broadcast, and the
// analyser sees one frame-rendering callback (PoppingOptions::renderFrame).
//
// Failure: a frame that fails on any rank fails on every rank (BrickedFrames agrees before
// it composites); rank 0's error ends the analysis and the requests, the others keep serving
// until then. An error of rank 0 alone between frames (its journal, a cancel) ends them too.
#include <cstddef>

#include "splat/bricks.h"

namespace splat::cli {

class BrickedFrameRequests {
  public:
    BrickedFrameRequests(BrickedFrames& frames, BrickGroup& group);
    /// Rank 0: ends the requests as failed unless end() was called.
    ~BrickedFrameRequests();
    BrickedFrameRequests(const BrickedFrameRequests&) = delete;
    BrickedFrameRequests& operator=(const BrickedFrameRequests&) = delete;

    /// Rank 0: the frame of `camera` by `renderer`, rendered by every rank's bricks.
    Image render(const CameraParams& camera, RendererKind renderer, RenderStats* stats);
    /// Ranks > 0: render the frames rank 0 asks for until it ends the requests; returns
    /// whether it ended them as a success.
    bool serve();
    /// Rank 0: ends serve() on every rank, with success or not (once).
    void end(bool ok);
    /// The frames rendered so far.
    std::size_t frames() const { return count_; }

  private:
    BrickedFrames& frames_;
    BrickGroup& group_;
    bool ended_ = false;
    std::size_t count_ = 0;
};

}  // namespace splat::cli
