#pragma once
// The IceT compositor of splat::mpi's BrickGroup (brick_group.h), built only with SPLAT_ICET:
// IceT 2 (in Debian inside ParaView: libvtkIceTCore, libvtkIceTMPI; the headers include
// nothing of ParaView or VTK), linked privately into splat::mpi alone.
#include <cstdint>
#include <utility>
#include <vector>

#include "splat/image.h"
#include "splat/settings.h"

struct IceTCommunicatorStruct;  // IceT.h's IceTCommunicator and IceTContext
struct IceTContextStruct;

namespace splat::mpi {

/// Whether IceT composites a frame of `frontToBack` on `ranks` ranks (brick b on rank
/// b % ranks): dvr and iso (IceT blends with `over` only), and every rank's bricks
/// consecutive in the order (one image per rank), which holds whenever there are no more
/// bricks than ranks. The same answer on every rank.
bool icetComposites(const std::vector<int>& frontToBack, RenderMode mode, int ranks);

/// An IceT context on MPI_COMM_WORLD, for the life of a BrickGroup.
class IcetCompositor {
  public:
    IcetCompositor();
    ~IcetCompositor();
    IcetCompositor(const IcetCompositor&) = delete;
    IcetCompositor& operator=(const IcetCompositor&) = delete;
    /// Blends this rank's partial images front to back, then the ranks' images by IceT's
    /// ordered compositing (radix-k) in the visibility order: the frame on rank 0 without
    /// its background (others: empty). Adds the bytes IceT sent to `sent`. Collective; only
    /// when icetComposites().
    Image composite(const std::vector<std::pair<int, Image>>& partials,
                    const std::vector<int>& frontToBack, int width, int height, RenderMode mode,
                    std::uint64_t* sent);

  private:
    IceTCommunicatorStruct* communicator_ = nullptr;
    IceTContextStruct* context_ = nullptr;
};

}  // namespace splat::mpi
