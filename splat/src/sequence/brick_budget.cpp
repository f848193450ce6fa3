// The per-process memory budget of bricked frames (splat/brick_budget.h).
#include "splat/brick_budget.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>

#include "splat/bricks.h"
#include "splat/error.h"

namespace splat {

std::uint64_t brickMemoryEstimate(std::uint64_t samples, int width, int height, int images,
                                  double splatShare) {
    const double sampleBytes = 4.0;  // float
    const double splatBytes = 26.0;  // SplatList: 3 x 2 + 5 x 4 bytes
    const std::uint64_t image = std::uint64_t(width) * std::uint64_t(height) * 16;  // RGBA float
    // Partial images kept for the composite, plus the composite's own buffers (the strips
    // received and sent, the frame on rank 0): three images.
    return kProcessBytes +
           std::uint64_t(double(samples) * (sampleBytes + splatShare * splatBytes)) +
           image * std::uint64_t(images + 3);
}

BrickChoice chooseBricks(const glm::ivec3& dims, const BrickBudget& budget, int maxBricks) {
    const int P = std::max(budget.ranks, 1);
    const std::uint64_t samples =
        std::uint64_t(dims.x) * std::uint64_t(dims.y) * std::uint64_t(dims.z);
    const int cap = int(std::min<std::uint64_t>(std::uint64_t(std::max(maxBricks, 1)), samples));
    const auto extra = [&](std::uint64_t n) {
        return std::uint64_t(double(n) * std::max(budget.extraSampleBytes, 0.0));
    };
    BrickChoice c;
    c.wholeFits = brickMemoryEstimate(samples, budget.width, budget.height, 1, budget.splatShare) +
                      extra(samples) <=
                  budget.rankBytes;
    // The largest brick of K bricks; 0 when the volume cannot be cut into K (a brick would
    // be left without samples: a thin volume).
    auto largestOf = [&](int K) {
        std::uint64_t largest = 0;
        try {
            for (const Brick& b : splitBricks(dims, K, budget.ghost).bricks)
                largest = std::max<std::uint64_t>(largest, b.loadedSamples());
        } catch (const Error&) {
            return std::uint64_t(0);
        }
        return largest;
    };
    int K = std::min(P, cap);
    while (K > 1 && largestOf(K) == 0) --K;  // more ranks than bricks: some stay idle
    for (;;) {
        const int held = budget.oneImageHeld ? 1 : (K + P - 1) / P;
        c.bricks = K;
        c.largestBrick = largestOf(K);
        c.rankBytes = brickMemoryEstimate(c.largestBrick, budget.width, budget.height, held,
                                          budget.splatShare) +
                      extra(c.largestBrick);
        c.withinBudget = c.rankBytes <= budget.rankBytes;
        if (c.withinBudget || c.wholeFits || K + P > cap || largestOf(K + P) == 0) break;
        K += P;
    }
    return c;
}

std::uint64_t defaultRankBytes(int ranks) {
    if (const char* v = std::getenv("SPLAT_MEMORY_BUDGET_MIB")) {
        const double mib = std::atof(v);
        if (mib > 0 && mib <= 1e9) return std::uint64_t(mib * 1048576.0);
    }
    int local = std::max(ranks, 1);
    for (const char* name : {"OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS"})
        if (const char* v = std::getenv(name)) {
            const int n = std::atoi(v);
            if (n >= 1) {
                local = n;
                break;
            }
        }
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    const std::uint64_t total =
        pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : (8ull << 30);
    return std::uint64_t(double(total) * 0.8) / std::uint64_t(local);
}

}  // namespace splat
