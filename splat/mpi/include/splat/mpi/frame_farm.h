#pragma once
// Frame-parallel sequences over MPI: the leader's FrameFarm hands the views of a
// sequence to the ranks dynamically (two in flight per worker, the leader renders one
// whenever no result is waiting), receives the frames and gives them to the sequence's sink
// in view order; every worker holds the same Scene and serves views until the leader stops
// the job. Frames do not depend on the rank that rendered them, so every output equals the
// single-process run's bit for bit.
#include <functional>
#include <memory>

#include "splat/frame_farm.h"
#include "splat/mpi/session.h"
#include "splat/scene.h"

namespace splat::mpi {

/// The leader's farm (install it with splat::installFrameFarm).
std::shared_ptr<FrameFarm> makeFrameFarm(Session& session);

/// Worker: builds the Scene with `build` (its error goes to the leader in the hello), then
/// renders the views the leader sends until it stops the job.
void serveFrames(Session& session, const std::function<Scene()>& build);

}  // namespace splat::mpi
