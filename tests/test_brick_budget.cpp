// The number of bricks from a memory budget per process (splat/brick_budget.h):
// the estimate's closed form, and the choice — the fewest bricks, a multiple of the ranks,
// that keep the busiest process within the budget.
#include <catch2/catch.hpp>

#include "splat/brick_budget.h"
#include "splat/bricks.h"

using namespace splat;

namespace {
constexpr std::uint64_t MiB = 1ull << 20;
}

TEST_CASE("brick budget: the estimate is samples, splats, images and the process", "[bricks]") {
    // 4 bytes per sample, 26 per splat for a quarter of them, RGBA float images (1 kept + 3
    // for the composite), 150 MiB for the process.
    CHECK(brickMemoryEstimate(1000000, 256, 256, 1, 0.25) ==
          kProcessBytes + 1000000ull * 4 + 250000ull * 26 + 256ull * 256 * 16 * 4);
    CHECK(brickMemoryEstimate(0, 10, 10, 5, 0.25) == kProcessBytes + 100ull * 16 * 8);
    CHECK(brickMemoryEstimate(100, 1, 1, 0, 0.0) == kProcessBytes + 400 + 48);
}

TEST_CASE("brick budget: the fewest bricks, a multiple of the ranks, within the budget",
          "[bricks]") {
    BrickBudget b;
    b.width = b.height = 256;
    b.ghost = 3;
    // 800^3 float = 1953 MiB of samples: about 2.6 GiB estimated whole.
    const glm::ivec3 big(800);
    for (int ranks : {1, 2, 3, 8})
        for (std::uint64_t budget : {400 * MiB, 700 * MiB, 1500 * MiB}) {
            INFO("ranks " << ranks << ", budget " << budget / MiB << " MiB");
            b.ranks = ranks;
            b.rankBytes = budget;
            const BrickChoice c = chooseBricks(big, b);
            CHECK_FALSE(c.wholeFits);
            CHECK(c.withinBudget);
            CHECK(c.bricks % ranks == 0);
            CHECK(c.rankBytes <= budget);
            // The estimate of the choice, from its own layout.
            const BrickLayout layout = splitBricks(big, c.bricks, b.ghost);
            std::uint64_t largest = 0;
            for (const Brick& brick : layout.bricks)
                largest = std::max<std::uint64_t>(largest, brick.loadedSamples());
            CHECK(c.largestBrick == largest);
            CHECK(c.rankBytes == brickMemoryEstimate(largest, 256, 256, c.bricks / ranks, 0.25));
            // One multiple fewer would not fit.
            if (c.bricks > ranks) {
                const BrickLayout fewer = splitBricks(big, c.bricks - ranks, b.ghost);
                std::uint64_t l = 0;
                for (const Brick& brick : fewer.bricks)
                    l = std::max<std::uint64_t>(l, brick.loadedSamples());
                CHECK(brickMemoryEstimate(l, 256, 256, (c.bricks - ranks) / ranks, 0.25) > budget);
            }
        }
    // Numbers: 8 ranks, 400 MiB each: (400 - 150 - 6) MiB / 10.5 bytes = 24.4 M samples per
    // brick, the volume 512 M: 24 bricks of 21.3 M + ghost layers (16 hold 32 M + ghosts).
    b.ranks = 8;
    b.rankBytes = 400 * MiB;
    CHECK(chooseBricks(big, b).bricks == 24);
    // A volume that fits one process: one brick per rank, to share the work.
    b.rankBytes = 8000 * MiB;
    const BrickChoice fits = chooseBricks(big, b);
    CHECK(fits.wholeFits);
    CHECK(fits.bricks == 8);
    // A budget below the process itself: nothing fits; the most bricks tried, said so.
    b.rankBytes = 100 * MiB;
    const BrickChoice none = chooseBricks(glm::ivec3(40), b, 64);
    CHECK_FALSE(none.withinBudget);
    CHECK(none.bricks == 64);
    // More ranks than a thin volume has bricks: as many as it can be cut into, the other
    // ranks idle.
    b.ranks = 30;
    const BrickChoice thin = chooseBricks(glm::ivec3(3, 3, 2), b);
    CHECK(thin.bricks >= 2);
    CHECK(thin.bricks <= 18);
    CHECK_NOTHROW(splitBricks(glm::ivec3(3, 3, 2), thin.bricks, 3));
}

TEST_CASE("brick budget: the default is 80% of physical memory over the ranks on the node",
          "[bricks]") {
    const std::uint64_t one = defaultRankBytes(1);
    CHECK(one > 256 * MiB);
    ::setenv("OMPI_COMM_WORLD_LOCAL_SIZE", "4", 1);
    CHECK(defaultRankBytes(64) == one / 4);  // 4 of the 64 ranks on this node
    ::unsetenv("OMPI_COMM_WORLD_LOCAL_SIZE");
    CHECK(defaultRankBytes(2) == one / 2);
}

TEST_CASE("brick budget: bytes per sample beyond one splat list (popping's renderers)",
          "[bricks]") {
    BrickBudget b;
    b.width = b.height = 64;
    b.ghost = 5;
    b.ranks = 2;
    b.rankBytes = 400 * MiB;
    b.extraSampleBytes = 45.5;  // popping's three renderers at a quarter of splats
    // phantom:200 (8 M samples): 150 MiB + 8 M x 56 bytes = 577 MiB whole, beyond 400 MiB;
    // two bricks of 200 x 200 x 105 = 4.2 M samples (ghost layers included): 374 MiB.
    const BrickChoice c = chooseBricks(glm::ivec3(200), b);
    CHECK_FALSE(c.wholeFits);
    CHECK(c.bricks == 2);
    CHECK(c.largestBrick == 4200000);
    CHECK(c.rankBytes == brickMemoryEstimate(4200000, 64, 64, 1, 0.25) + 4200000ull * 455 / 10);
    CHECK(c.rankBytes <= b.rankBytes);
    // Without the extra bytes the whole volume fits (8 M x 10.5 bytes + 150 MiB = 230 MiB).
    b.extraSampleBytes = 0;
    CHECK(chooseBricks(glm::ivec3(200), b).wholeFits);
}

TEST_CASE("brick budget: one process compositing as it renders holds one partial image",
          "[bricks]") {
    BrickBudget b;
    b.width = b.height = 256;  // 1 MiB per RGBA float image
    b.ghost = 2;
    b.ranks = 1;
    b.splatShare = 1.0;
    b.rankBytes = 256 * MiB;
    // 512^3 samples at 30 bytes each (a float and a splat): one image per brick held would
    // need more bricks than 4096 images of 1 MiB allow; one image held fits with a few dozen.
    const BrickChoice perBrick = chooseBricks(glm::ivec3(512), b);
    CHECK_FALSE(perBrick.withinBudget);
    b.oneImageHeld = true;
    const BrickChoice one = chooseBricks(glm::ivec3(512), b);
    CHECK(one.withinBudget);
    CHECK(one.bricks < 200);
    CHECK(one.rankBytes == brickMemoryEstimate(one.largestBrick, 256, 256, 1, 1.0));
    CHECK(one.rankBytes <= b.rankBytes);
}
