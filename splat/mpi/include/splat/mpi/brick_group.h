#pragma once
// Sort-last bricked rendering over MPI (issue 26): the BrickGroup of splat/bricks.h on the
// ranks of the job. Compositing is direct-send (Hsu 1993, "Segmented ray casting for data
// parallel volume rendering"; Eilemann & Pajarola 2007): the image rows are cut into one
// strip per rank, every rank sends each strip of its partial images to that strip's rank
// (one MPI_Alltoallv), which composites the strip's K fragments in visibility order; the
// strips are gathered on rank 0 (MPI_Gatherv). Each rank sends about (P-1)/P of its
// partial images and receives K/P strips: bytes per rank ~ 16 W H (K/P + 1/P), whatever P.
#include <memory>

#include "splat/bricks.h"
#include "splat/mpi/session.h"

namespace splat::mpi {

std::unique_ptr<BrickGroup> makeBrickGroup(Session& session);

}  // namespace splat::mpi
