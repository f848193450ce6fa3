// OpenVDB grids rendered without a dense copy: in bricks whose samples are read from the
// grid's tree, the bricks that hold only the background value b neither loaded nor rendered
// (splat/bricks.h emptyBrickImage). The image equals the dense copy's in every renderer and
// mode, b = 3 (max abs difference <= 1e-5 of the peak); where b has opacity, the empty bricks
// are rendered, not skipped. The CLI renders a .vdb that way by itself, and a volume beyond
// the memory budget in bricks one after another (docs/parallel.md "Larger than memory").
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include "image_diff.h"
#include "sparse_util.h"
#include "splat/bricks.h"
#include "splat/image_io.h"
#include "splat/render.h"
#include "splat/sparse_files.h"
#include "splat/volume_io.h"

using namespace splat;
using namespace splat::test;

namespace {

/// The grid of `spec` in `bricks` bricks, its empty bricks told to BrickedFrames.
Image renderSparse(const std::string& spec, const RenderSettings& s, int bricks, BrickStats* st) {
    const Volume g = volumeGeometry(spec, LoadOptions{}, nullptr);
    LocalBrickGroup group;
    return renderBricked(
        g, [&](const Brick& b) { return loadVolumeBrick(spec, LoadOptions{}, b.loadLo, b.loadHi); },
        s, bricks, group, st, BrickComposite::Exact,
        [&](const Brick& b) { return brickHoldsOnlyBackground(spec, LoadOptions{}, b.loadLo, b.loadHi); });
}

/// The dense copy `v` in `bricks` bricks, every one loaded and rendered.
Image renderDenseBricks(const Volume& v, const RenderSettings& s, int bricks) {
    Volume g = v;
    g.data.clear();
    LocalBrickGroup group;
    return renderBricked(
        g,
        [&](const Brick& b) {
            Volume out = makeVolume(b.loadHi - b.loadLo, v.spacing, v.source);
            out.origin = v.world(glm::dvec3(b.loadLo));
            out.background = v.background;
            for (int k = 0; k < out.dims.z; ++k)
                for (int j = 0; j < out.dims.y; ++j)
                    for (int i = 0; i < out.dims.x; ++i)
                        out.at(i, j, k) = v.at(b.loadLo.x + i, b.loadLo.y + j, b.loadLo.z + k);
            return out;
        },
        s, bricks, group);
}

RenderSettings frameOf(RendererKind r, RenderMode m, Classification cl) {
    RenderSettings s;
    s.renderer = r;
    s.mode = m;
    s.classification = cl;
    s.camera.width = s.camera.height = 36;
    s.camera.azimuthDeg = 25;
    s.camera.elevationDeg = 17;
    s.isoLevel = 0.4;
    s.isoNormalized = true;
    s.quality.referenceTolerance = 1e-7;  // the reference's pieces within its error control
    s.threads = 2;
    if (cl == Classification::Post) {
        // Transparent at b = 3 and below (the negative blob): post-classified, a b with
        // opacity would fill the box with haze, which bricks do not draw as one volume
        // (automaticBricks renders such frames whole).
        s.transfer.normalized = false;
        s.transfer.points = {{3.0f, {0.2f, 0.2f, 0.2f, 0.0f}}, {13.0f, {1.0f, 0.9f, 0.8f, 0.9f}}};
    }
    return s;
}

}  // namespace

TEST_CASE("sparse VDB: a brick's emptiness comes from the tree", "[vdb][bricks]") {
    if (!openVdbAvailable()) {
        WARN("splat is built without OpenVDB (SPLAT_OPENVDB): skipped");
        return;
    }
    SPARSE_DATA_OR_SKIP(data);
    const std::string spec = (data / "blobs.vdb").string();
    const Volume dense = loadVolume(spec);
    REQUIRE(dense.background == 3.0f);
    const BrickLayout layout = splitBricks(dense.dims, 24, 5);
    int empty = 0;
    for (const Brick& b : layout.bricks) {
        const Volume v = loadVolumeBrick(spec, LoadOptions{}, b.loadLo, b.loadHi);
        const bool allB = std::all_of(v.data.begin(), v.data.end(),
                                      [](float x) { return x == 3.0f; });
        CHECK(brickHoldsOnlyBackground(spec, LoadOptions{}, b.loadLo, b.loadHi) == allB);
        empty += allB;
    }
    CHECK(empty >= 6);
    CHECK(empty < 24);
    CHECK_FALSE(brickHoldsOnlyBackground((data / "blobs.nii.gz").string(), LoadOptions{},
                                         glm::ivec3(0), glm::ivec3(2)));
}

TEST_CASE("sparse VDB: bricks from the tree, empty ones skipped, render the dense copy's image",
          "[vdb][bricks][images]") {
    if (!openVdbAvailable()) {
        WARN("splat is built without OpenVDB (SPLAT_OPENVDB): skipped");
        return;
    }
    SPARSE_DATA_OR_SKIP(data);
    const std::string spec = (data / "blobs.vdb").string();
    const Volume dense = loadVolume(spec);
    for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet, RendererKind::Reference})
        for (RenderMode m : {RenderMode::Dvr, RenderMode::Mip, RenderMode::Xray, RenderMode::Iso})
            for (Classification cl : {Classification::Pre, Classification::Post}) {
                if (cl == Classification::Post && m != RenderMode::Dvr) continue;
                const RenderSettings s = frameOf(r, m, cl);
                const Image whole = render(dense, s);
                const double top = peakOf(whole);
                REQUIRE(top > 0);
                BrickStats st;
                const Image sparse = renderSparse(spec, s, 12, &st);
                INFO("renderer " << toString(r) << " mode " << toString(m) << " classification "
                                 << int(cl));
                CHECK(st.empty >= 2);
                // The skipped bricks change nothing: the same bricks all loaded and rendered.
                CHECK(maxDiff(sparse, renderDenseBricks(dense, s, 12)) <= 1e-6 * top);
                // And the dense copy's own image. The axis-aligned splatter's x-ray seam at
                // brick faces reaches 6.4e-5 of the peak here (the NIfTI's bricks alike).
                const double bound = r == RendererKind::Axis && m == RenderMode::Xray ? 1e-4 : 1e-5;
                CHECK(maxDiff(sparse, whole) <= bound * top);
            }
}

TEST_CASE("sparse VDB: where b has opacity, no brick is skipped and splat render draws it whole",
          "[vdb][bricks][images][cli]") {
    if (!openVdbAvailable()) {
        WARN("splat is built without OpenVDB (SPLAT_OPENVDB): skipped");
        return;
    }
    SPARSE_DATA_OR_SKIP(data);
    const std::string spec = (data / "blobs.vdb").string();
    const Volume dense = loadVolume(spec);
    RenderSettings s = frameOf(RendererKind::Reference, RenderMode::Dvr, Classification::Pre);
    // Opacity 0.02 per unit at b = 3: a haze through the whole box.
    s.transfer.normalized = false;
    s.transfer.points = {{0.0f, {0.5f, 0.5f, 0.5f, 0.02f}}, {13.0f, {1.0f, 0.9f, 0.8f, 0.9f}}};
    const Volume g = volumeGeometry(spec, LoadOptions{}, nullptr);
    Brick whole;
    whole.hi = whole.loadHi = g.dims;
    CHECK_FALSE(emptyBrickImage(g, brickSettings(s, g, whole, g.dims)).has_value());
    const Image full = render(dense, s);
    BrickStats st;
    const Image sparse = renderSparse(spec, s, 12, &st);
    CHECK(st.empty >= 2);  // known empty, rendered all the same
    CHECK(maxDiff(sparse, full) <= 1e-5 * peakOf(full));

    const auto dir = testTmpDir("vdb_sparse_haze");
    const std::string tf = (dir / "haze.json").string();
    {
        std::ofstream out(tf);
        out << R"({"domain": "absolute", "unit_distance": 1, "points": )"
            << R"([[0, 0.5, 0.5, 0.5, 0.02], [13, 1, 0.9, 0.8, 0.9]]})";
    }
    const std::string a = (dir / "vdb.exr").string(), b = (dir / "nii.exr").string();
    const RunResult rv = runSplat({"render", spec, "--tf", tf, "--size", "40x40", "-o", a});
    REQUIRE(rv.status == 0);
    CHECK(rv.out.find(" bricks (ghost layers") == std::string::npos);
    REQUIRE(runSplat({"render", (data / "blobs.nii.gz").string(), "--tf", tf, "--size", "40x40",
                      "-o", b})
                .status == 0);
    const Image iv = readImage(a), in = readImage(b);
    CHECK(maxDiff(iv, in) <= 1e-5 * peakOf(in));
}

TEST_CASE("sparse VDB: splat render of a .vdb goes through its bricks and equals the NIfTI's",
          "[vdb][bricks][cli]") {
    if (!openVdbAvailable()) {
        WARN("splat is built without OpenVDB (SPLAT_OPENVDB): skipped");
        return;
    }
    SPARSE_DATA_OR_SKIP(data);
    const auto dir = testTmpDir("vdb_sparse_cli");
    // dvr: transparent at b = 3 and below (the default ramp over [1, 13] gives b opacity:
    // then the grid is drawn whole, the case above).
    const std::string tf = (dir / "clear_b.json").string();
    {
        std::ofstream out(tf);
        out << R"({"domain": "absolute", "unit_distance": 1, "points": )"
            << R"([[3, 0.2, 0.2, 0.2, 0], [13, 1, 0.9, 0.8, 0.9]]})";
    }
    for (const char* mode : {"mip", "dvr"}) {
        const std::string a = (dir / (std::string(mode) + "_vdb.exr")).string();
        const std::string b = (dir / (std::string(mode) + "_nii.exr")).string();
        std::vector<std::string> common = {"--mode", mode, "--size", "40x40", "--azimuth",
                                           "30", "--elevation", "20", "--threads", "2"};
        if (std::string(mode) == "dvr") common.insert(common.end(), {"--tf", tf});
        std::vector<std::string> args = {"render", (data / "blobs.vdb").string(), "-o", a};
        args.insert(args.end(), common.begin(), common.end());
        const RunResult rv = runSplat(args);
        REQUIRE(rv.status == 0);
        CHECK(rv.out.find(" bricks (ghost layers") != std::string::npos);
        CHECK(rv.errLines().empty());
        args = {"render", (data / "blobs.nii.gz").string(), "-o", b};
        args.insert(args.end(), common.begin(), common.end());
        REQUIRE(runSplat(args).status == 0);
        const Image iv = readImage(a), in = readImage(b);
        INFO(mode);
        CHECK(maxDiff(iv, in) <= 1e-5 * peakOf(in));
    }
}

TEST_CASE("larger than memory: splat render beyond the budget renders bricks one after another",
          "[bricks][cli]") {
    // SPLAT_MEMORY_BUDGET_MIB sets the budget (brick_budget.h defaultRankBytes): 160 MiB
    // leaves 10 MiB beyond the process itself, less than phantom:160's whole-volume estimate.
    const auto dir = testTmpDir("auto_bricks");
    const std::string a = (dir / "whole.exr").string(), b = (dir / "bricked.exr").string();
    const std::vector<std::string> common = {"synthetic:phantom:160", "--mode", "mip",
                                             "--renderer", "axis", "--size", "48x48",
                                             "--azimuth", "33", "--elevation", "21"};
    std::vector<std::string> args = {"render", "-o", a};
    args.insert(args.end(), common.begin(), common.end());
    const RunResult whole = runSplat(args);
    REQUIRE(whole.status == 0);
    CHECK(whole.out.find(" bricks (ghost layers") == std::string::npos);
    ::setenv("SPLAT_MEMORY_BUDGET_MIB", "160", 1);
    args = {"render", "-o", b};
    args.insert(args.end(), common.begin(), common.end());
    const RunResult bricked = runSplat(args);
    ::unsetenv("SPLAT_MEMORY_BUDGET_MIB");
    REQUIRE(bricked.status == 0);
    REQUIRE(bricked.errLines().size() == 1);
    CHECK(bricked.errLines()[0].find("do not fit the memory budget of 160 MiB") !=
          std::string::npos);
    CHECK(bricked.out.find(" bricks (ghost layers") != std::string::npos);
    const Image iw = readImage(a), ib = readImage(b);
    // The axis-aligned splatter's bricks composite exactly (test_bricks.cpp: <= 1e-5).
    CHECK(maxDiff(iw, ib) <= 1e-5 * peakOf(iw));
}
