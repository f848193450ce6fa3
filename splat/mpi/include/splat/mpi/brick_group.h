#pragma once
// Sort-last bricked rendering over MPI: the BrickGroup of splat/bricks.h on the
// ranks of the job, with two compositors of the partial images (docs/parallel.md,
// "Direct-send beside IceT"):
//
// - Direct-send (Hsu 1993, "Segmented ray casting for data parallel volume rendering";
//   Eilemann & Pajarola 2007): the image rows are cut into one strip per rank; every rank
//   sends each strip of its partial images to that strip's rank (one MPI_Alltoallv), which
//   composites the strip's K fragments in visibility order; the strips are gathered on rank
//   0 (MPI_Gatherv). Sparse: of every row of a strip only the span from its first to its last
//   pixel that is not transparent (all four floats zero) is sent, so a brick costs the part
//   of the frame it covers, not the frame. Bit for bit the dense exchange's image (the same
//   blends in the same order; transparent pixels are rebuilt exactly).
// - IceT (Moreland et al., SC 2011; radix-k, Kendall et al., EGPGV 2010), when splat is
//   built with it (SPLAT_ICET): ordered blending of one image per rank in the bricks'
//   visibility order. Used for dvr and iso when every rank's bricks are consecutive in that
//   order (always with one brick per rank): a rank blends its own first. Otherwise (mip,
//   xray: IceT blends only with `over`; a rank's bricks interleaved with another's)
//   direct-send composites the frame. The image equals direct-send's within float rounding
//   (IceT associates the blends in another order).
#include <memory>

#include "splat/bricks.h"
#include "splat/mpi/session.h"

namespace splat::mpi {

enum class Compositor { Direct, Icet };

/// Whether this splat::mpi was built with IceT (SPLAT_ICET).
bool icetBuilt();

/// The group of every rank of `session`. Compositor::Icet without icetBuilt() throws
/// splat::Error.
std::unique_ptr<BrickGroup> makeBrickGroup(Session& session,
                                           Compositor compositor = Compositor::Direct);

/// The bytes this process sent in `group`'s last composite (a group of makeBrickGroup;
/// benchmarks: tools/bench/icet/icet_compare.cpp). BrickGroup::composite's count adds the
/// bytes received.
std::uint64_t lastBytesSent(const BrickGroup& group);

}  // namespace splat::mpi
