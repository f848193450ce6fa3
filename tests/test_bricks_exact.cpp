// Exact bricks of the image-aligned splatter (splat/slab_sheets.h): every slab's
// sheets summed over the bricks before compositing give the one-process frame to float
// rounding, for odd sizes and K not a power of 2; the fast path (partial images) does not.
#include <catch2/catch.hpp>
#include <cmath>

#include "splat/bricks.h"
#include "splat/scene.h"
#include "splat/slab_sheets.h"
#include "splat/volume.h"
#include "splat/volume_io.h"
#include "image_diff.h"

using namespace splat;
using namespace splat::test;

namespace {

Image wholeFrame(const std::string& spec, const RenderSettings& s) {
    const Volume v = loadVolume(spec);
    return Scene(v, s).render(s);
}

Image brickedFrame(const std::string& spec, const RenderSettings& s, int bricks,
                   BrickComposite composite, BrickStats* st = nullptr) {
    bool alone = false;
    const Volume geometry = volumeGeometry(spec, {}, &alone);
    LocalBrickGroup group;
    return renderBricked(
        geometry, [&](const Brick& b) { return loadVolumeBrick(spec, {}, b.loadLo, b.loadHi); }, s,
        bricks, group, st, composite);
}

RenderSettings sheetSettings(RenderMode mode) {
    RenderSettings s;
    s.renderer = RendererKind::Sheet;
    s.mode = mode;
    s.camera.width = 40;
    s.camera.height = 34;
    s.camera.azimuthDeg = 25;
    s.camera.elevationDeg = 15;
    s.quality.earlyTermination = 0;  // a bricked frame integrates every brick
    s.quality.tileSize = 16;         // several tiles, some cut by the image's edge
    // A voxel covers < 1 pixel here: xray renders with EWA (auto), in the bricks too.
    if (mode == RenderMode::Dvr) s.transfer = TransferFunction::preset("ct-bone");
    return s;
}

}  // namespace

TEST_CASE("bricks exact: the image-aligned splatter's bricks equal one process within 1e-5",
          "[bricks]") {
    for (const std::string spec : {"synthetic:phantom:23", "synthetic:phantom:27"})
        for (RenderMode mode : {RenderMode::Dvr, RenderMode::Mip, RenderMode::Xray}) {
            const RenderSettings s = sheetSettings(mode);
            const Image one = wholeFrame(spec, s);
            const float peak = peakOf(one);
            REQUIRE(peak > 0);
            for (int k : {2, 3, 5}) {
                BrickStats st;
                const Image bricked = brickedFrame(spec, s, k, BrickComposite::Exact, &st);
                INFO(spec << " " << toString(mode) << " K=" << k);
                CHECK(maxDiff(one, bricked) <= 1e-5f * peak);
                CHECK(st.rendered == k);
                CHECK(st.bytesExchanged == 0);  // one process
            }
        }
}

TEST_CASE("bricks exact: back to front, a thin slab and post-classified shading agree too",
          "[bricks]") {
    RenderSettings s = sheetSettings(RenderMode::Dvr);
    s.order = CompositeOrder::BackToFront;
    s.quality.slab = 0.5;
    const std::string spec = "synthetic:phantom:25";
    const Image one = wholeFrame(spec, s);
    CHECK(maxDiff(one, brickedFrame(spec, s, 3, BrickComposite::Exact)) <= 1e-5f * peakOf(one));
    // Post-classified with shading (gradient channels, ghost layers give the gradients).
    s.order = CompositeOrder::FrontToBack;
    s.classification = Classification::Post;
    s.shading.enabled = true;
    const Image post = wholeFrame(spec, s);
    CHECK(maxDiff(post, brickedFrame(spec, s, 5, BrickComposite::Exact)) <= 1e-5f * peakOf(post));
}

TEST_CASE("bricks exact: the fast composite has the seam the exact one removes", "[bricks]") {
    const RenderSettings s = sheetSettings(RenderMode::Xray);
    const std::string spec = "synthetic:phantom:23";
    const Image one = wholeFrame(spec, s);
    const float fast = maxDiff(one, brickedFrame(spec, s, 3, BrickComposite::Fast));
    const float exact = maxDiff(one, brickedFrame(spec, s, 3, BrickComposite::Exact));
    CHECK(fast > 1e-3f * peakOf(one));
    CHECK(exact <= 1e-5f * peakOf(one));
}

TEST_CASE("bricks exact: a slab group fits its byte budget", "[bricks]") {
    SlabLayout L;
    L.tiles = 64;
    L.tileSize = 32;
    L.channels = 4;
    L.slabs = 400;
    CHECK(L.blockFloats() == 4096);
    CHECK(slabGroup(L, std::size_t(64) << 20) == 64);  // 1 MiB per slab of the frame
    CHECK(slabGroup(L, 100) == 1);                     // at least one slab
    CHECK(slabGroup(L, std::size_t(1) << 40) == 400);  // at most the frame
}

TEST_CASE("bricks exact: a brick's sheets cut group by group equal its sheets at once",
          "[bricks]") {
    // Memory stays bounded by one group of slabs: cutting the kernels that straddle a group's
    // ends into its slabs alone must give each slab what the whole frame's sweep gives it.
    const std::string spec = "synthetic:phantom:21";
    RenderSettings s = sheetSettings(RenderMode::Dvr);
    bool alone = false;
    const Volume whole = volumeGeometry(spec, {}, &alone);
    const BrickLayout layout = splitBricks(whole.dims, 2, 3);
    const Brick& brick = layout.bricks[1];
    auto v = std::make_shared<const Volume>(loadVolumeBrick(spec, {}, brick.loadLo, brick.loadHi));
    RenderSettings bs = brickSettings(s, whole, brick, whole.dims);
    bs.clipping.planes.clear();
    const Scene scene(v, bs);
    BrickSheets sheets(scene, bs, brick.lo - brick.loadLo, brick.hi - brick.loadLo, whole);
    REQUIRE(sheets.splats() > 0);
    const SlabLayout L = sheets.plan(sheets.nearest(), sheets.farthest());
    REQUIRE(L.slabs > 8);
    const std::size_t B = L.blockFloats();
    std::vector<float> once(std::size_t(L.tiles) * L.slabs * B, 0.0f);
    std::vector<int> onceRects(std::size_t(L.tiles) * L.slabs * 4, kNoRect);
    sheets.add(0, L.slabs, once.data(), onceRects.data());
    float peak = 0;
    for (float x : once) peak = std::max(peak, std::abs(x));
    REQUIRE(peak > 0);
    const std::uint32_t G = 3;  // slabs per group: most kernels straddle a group's end
    float worst = 0;
    int rectsDiffer = 0;
    for (std::uint32_t first = 0; first < L.slabs; first += G) {
        const std::uint32_t n = std::min(G, L.slabs - first);
        std::vector<float> part(std::size_t(L.tiles) * n * B, 0.0f);
        std::vector<int> rects(std::size_t(L.tiles) * n * 4, kNoRect);
        sheets.add(first, n, part.data(), rects.data());
        for (int t = 0; t < L.tiles; ++t)
            for (std::uint32_t k = 0; k < n; ++k) {
                const float* a = &part[(std::size_t(t) * n + k) * B];
                const float* b = &once[(std::size_t(t) * L.slabs + first + k) * B];
                for (std::size_t q = 0; q < B; ++q) worst = std::max(worst, std::abs(a[q] - b[q]));
                for (int c = 0; c < 4; ++c)
                    rectsDiffer += rects[(std::size_t(t) * n + k) * 4 + c] !=
                                   onceRects[(std::size_t(t) * L.slabs + first + k) * 4 + c];
            }
    }
    CHECK(worst <= 1e-6f * peak);
    CHECK(rectsDiffer == 0);
}
