#pragma once
// How many bricks a frame needs so that each process stays within a memory budget
// (docs/parallel.md): a pure function of the volume's size, the image and the
// ranks, so that it is tested with numbers and every rank computes the same choice.
//
// A process rendering bricks holds, at its peak: the largest of its bricks (ghost layers
// included) as float samples, that brick's splat list, one partial image per brick it
// renders plus the compositing buffers, and the process itself (libraries, threads, tables).
// The splat list is not known before classification; the estimate assumes a share of the
// samples become splats (26 bytes each: i, j, k as 16-bit, d - b, rho and emission as float).
#include <cstdint>
#include <glm/glm.hpp>

namespace splat {

struct BrickBudget {
    std::uint64_t rankBytes = 0;  ///< memory per process
    int ranks = 1;                ///< processes rendering the frame
    int width = 0, height = 0;    ///< the image
    int ghost = 0;                ///< ghost layers (ghostLayers())
    /// Share of the samples assumed to become splats (the transfer function decides; the
    /// phantom's skull preset keeps 3%, a head MR 10-40%).
    double splatShare = 0.25;
    /// Bytes per sample of the brick held beyond its samples and one splat list: more
    /// renderers' structures (`splat popping` holds one Scene per renderer: another splat
    /// list each, the reference's field grid of 20 bytes per sample, the image-aligned
    /// splatter's projected splats).
    double extraSampleBytes = 0;
    /// One process that composites each brick's image into the frame as soon as it is
    /// rendered (BrickedFrames on one process, every renderer but the image-aligned
    /// splatter's slab composite): one partial image held, whatever the number of bricks.
    bool oneImageHeld = false;
};

/// The estimated peak bytes of a process holding a brick of `samples` samples (ghost layers
/// included) and `images` partial images of width x height.
std::uint64_t brickMemoryEstimate(std::uint64_t samples, int width, int height, int images,
                                  double splatShare);

/// The fixed part of brickMemoryEstimate: the process, its libraries and threads (measured:
/// about 150 MiB for `splat render` here).
constexpr std::uint64_t kProcessBytes = 150ull << 20;

struct BrickChoice {
    int bricks = 1;                  ///< K: a multiple of the ranks
    bool wholeFits = false;          ///< the whole volume fits one process's budget
    bool withinBudget = false;       ///< the busiest process of K bricks fits the budget
    std::uint64_t rankBytes = 0;     ///< the estimate for the busiest process with K bricks
    std::uint64_t largestBrick = 0;  ///< its largest brick, samples
};

/// The fewest bricks K, a multiple of budget.ranks (each rank gets K / ranks bricks, rendered
/// one after another), for which the busiest process's estimate is within the budget; K =
/// ranks when the volume fits whole (then bricks only share the work). When no K up to
/// `maxBricks` fits, the largest tried, with withinBudget false.
BrickChoice chooseBricks(const glm::ivec3& dims, const BrickBudget& budget, int maxBricks = 4096);

/// The default budget per process: the environment variable SPLAT_MEMORY_BUDGET_MIB when set
/// (MiB, > 0), else 80% of the machine's physical memory divided by the processes on this
/// node (OpenMPI's OMPI_COMM_WORLD_LOCAL_SIZE, MPICH's MPI_LOCALNRANKS, else `ranks`: all on
/// this node).
std::uint64_t defaultRankBytes(int ranks);

}  // namespace splat
