// OpenVDB files (splat/sparse_files.h) written by python3-openvdb
// (tests/sparse/make_sparse_data.py): a grid equals the NIfTI nibabel wrote of the same
// samples (inactive voxels hold the background, which becomes b); grids are chosen by name
// or by the default rule; active tiles fill their boxes; a turned transform, a vector grid,
// a truncated, damaged or foreign file give one line; bricks read alone equal crops. Skipped with a
// message when splat is built without OpenVDB (SPLAT_OPENVDB), except for the line that
// says so.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_util.h"
#include "sparse_util.h"
#include "splat/bricks.h"
#include "splat/error.h"
#include "splat/sparse_files.h"
#include "splat/volume_io.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

std::string loadError(const std::string& spec, const LoadOptions& options = {}) {
    try {
        loadVolume(spec, options);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

/// The small grid the script copies from numpy: (i * 30 + j * 6 + k) % 7 + 1 at voxel
/// (i, j, k) of a 4 x 5 x 6 array.
float small(int i, int j, int k) { return float((i * 30 + j * 6 + k) % 7 + 1); }

}  // namespace

#define OPENVDB_OR_SKIP()                                                              \
    if (!openVdbAvailable()) {                                                         \
        WARN(                                                                          \
            "splat is built without OpenVDB (SPLAT_OPENVDB; Debian: libopenvdb-dev): " \
            "skipped");                                                                \
        return;                                                                        \
    }

TEST_CASE("vdb: without OpenVDB a .vdb file is one line", "[vdb]") {
    if (openVdbAvailable()) return;
    const fs::path p = testTmpDir() / "absent.vdb";
    std::ofstream(p) << "x";
    CHECK(loadError(p.string()).find("built without OpenVDB") != std::string::npos);
}

TEST_CASE("vdb: a grid equals the NIfTI of the same samples", "[vdb]") {
    OPENVDB_OR_SKIP();
    SPARSE_DATA_OR_SKIP(data);
    const Volume nii = loadVolume((data / "same.nii.gz").string());
    const Volume v = loadVolume((data / "same.vdb").string());
    REQUIRE(v.dims == nii.dims);
    std::size_t wrong = 0;
    for (std::size_t n = 0; n < v.voxelCount(); ++n) wrong += v.value(n) != nii.value(n);
    CHECK(wrong == 0);
    CHECK(v.spacing == glm::dvec3(0.75, 1.125, 1.25));
    CHECK(v.origin == glm::dvec3(2.0, -3.0, 5.0));
    CHECK(v.spacing == nii.spacing);
    CHECK(v.origin == nii.origin);
    CHECK(v.background == 3.0f);
    CHECK(v.backgroundSource == "OpenVDB grid background");
    CHECK(v.source.find("OpenVDB float grid 'density'") != std::string::npos);
}

TEST_CASE("vdb: grids by name, the default rule, tiles and transforms", "[vdb]") {
    OPENVDB_OR_SKIP();
    SPARSE_DATA_OR_SKIP(data);
    const std::string grids = (data / "grids.vdb").string();
    const auto list = listVdbGrids(grids);
    REQUIRE(list.size() == 3);
    std::string firstFloat;
    for (const auto& g : list)
        if (firstFloat.empty() && g.valueType == "float") firstFloat = g.name;
    // No `density`: the first float grid.
    const Volume d = loadVolume(grids);
    CHECK(d.source.find("grid '" + firstFloat + "'") != std::string::npos);

    LoadOptions o;
    o.grid = "temperature";
    const Volume t = loadVolume(grids, o);
    REQUIRE(t.dims == glm::ivec3(4, 5, 6));
    CHECK(t.spacing == glm::dvec3(0.25));
    CHECK(t.origin == glm::dvec3(2.5, 5.0, 7.5));
    CHECK(t.background == -1.0f);
    std::size_t wrong = 0;
    for (int k = 0; k < 6; ++k)
        for (int j = 0; j < 5; ++j)
            for (int i = 0; i < 4; ++i) wrong += t.at(i, j, k) != 2.0f * small(i, j, k);
    CHECK(wrong == 0);

    o.grid = "smoke";
    const Volume s = loadVolume(grids, o);
    // The voxels at 0..3 x 0..4 x 0..5 and an active 8^3 tile at 16..23 x 0..7 x 0..7.
    REQUIRE(s.dims == glm::ivec3(24, 8, 8));
    CHECK(s.at(1, 2, 3) == small(1, 2, 3));
    CHECK(s.at(16, 0, 0) == 2.5f);
    CHECK(s.at(23, 7, 7) == 2.5f);
    CHECK(s.at(10, 4, 4) == 0.0f);  // inactive: the background
    CHECK(s.at(3, 7, 7) == 0.0f);
    for (const auto& g : list)
        if (g.name == "smoke") {
            CHECK(g.activeVoxels == 4u * 5u * 6u + 512u);
            CHECK(g.bboxMax == glm::ivec3(23, 7, 7));
            CHECK(g.background == 0.0);
        }

    o.grid = "velocity";
    CHECK(loadError(grids, o).find("grid 'velocity' holds vec3s values") != std::string::npos);
    o.grid = "nope";
    const std::string e = loadError(grids, o);
    CHECK(e.find("no grid named 'nope' (grids: ") != std::string::npos);
    CHECK(e.find("velocity") != std::string::npos);

    const std::string turned = loadError((data / "rotated.vdb").string());
    CHECK(turned.find("not a positive scale per axis and a translation") != std::string::npos);
    CHECK_FALSE(listVdbGrids((data / "rotated.vdb").string())[0].axisAligned);
}

TEST_CASE("vdb: truncated and foreign files are one line", "[vdb][errors]") {
    OPENVDB_OR_SKIP();
    SPARSE_DATA_OR_SKIP(data);
    const fs::path tmp = testTmpDir("vdb_bad");
    const std::string bytes = readTextFile(data / "same.vdb");
    for (std::size_t keep : {std::size_t(0), std::size_t(7), std::size_t(40), bytes.size() / 3,
                             bytes.size() / 2, bytes.size() - 9}) {
        INFO("first " << keep << " bytes");
        const fs::path p = tmp / "cut.vdb";
        std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(keep));
        const std::string e = loadError(p.string());
        CHECK(e.find("cut.vdb") != std::string::npos);
        CHECK(e.find('\n') == std::string::npos);
    }
    // Cut anywhere (every 97th length of a file of compressed leaves): OpenVDB reads a cut
    // block's length into an uninitialised variable, so without the zero-padded stream
    // (openvdb_file.cpp) the size it allocates differs from process to process.
    const std::string blobs = readTextFile(data / "blobs.vdb");
    for (std::size_t keep = 0; keep < blobs.size(); keep += 97) {
        INFO("blobs.vdb cut to " << keep << " bytes");
        const fs::path p = tmp / "cut_blobs.vdb";
        std::ofstream(p, std::ios::binary).write(blobs.data(), std::streamsize(keep));
        const std::string e = loadError(p.string());
        CHECK(e.find("cut_blobs.vdb: ") != std::string::npos);
        CHECK((e.find("malformed OpenVDB file") != std::string::npos ||
               e.find("not a readable OpenVDB file") != std::string::npos));
        CHECK(e.find('\n') == std::string::npos);
    }
    // Bytes changed inside the tree: OpenVDB aborts on the first (a leaf's header, byte
    // 9311 of this file), throws on the second; the child process that reads the file first
    // turns the abort into one line (parse_in_child.h).
    for (const auto& [at, value] : {std::pair<std::size_t, char>{9311, char(0x9b)},
                                    std::pair<std::size_t, char>{15736, char(0x11)}}) {
        INFO("byte " << at);
        REQUIRE(at < bytes.size());
        std::string changed = bytes;
        changed[at] = value;
        const fs::path p = tmp / "changed.vdb";
        std::ofstream(p, std::ios::binary).write(changed.data(), std::streamsize(changed.size()));
        const std::string e = loadError(p.string());
        CHECK(e.find("changed.vdb: ") != std::string::npos);
        CHECK((e.find("malformed OpenVDB file") != std::string::npos ||
               e.find("not a readable OpenVDB file") != std::string::npos));
        CHECK(e.find('\n') == std::string::npos);
    }
    const fs::path foreign = tmp / "text.vdb";
    std::ofstream(foreign) << "this is not an OpenVDB file, just text\n";
    CHECK(loadError(foreign.string()).find("not a readable OpenVDB file") != std::string::npos);
}

TEST_CASE("vdb: bricks read alone equal crops of the whole volume", "[vdb][bricks]") {
    OPENVDB_OR_SKIP();
    SPARSE_DATA_OR_SKIP(data);
    for (const std::string& grid : {std::string(), std::string("smoke")}) {
        const std::string spec = (data / (grid.empty() ? "same.vdb" : "grids.vdb")).string();
        INFO(spec << " " << grid);
        LoadOptions o;
        o.grid = grid;
        checkBrickReadAlone(spec, o, glm::ivec3(3, 1, 2), glm::ivec3(2, 1, 1));
    }
}

TEST_CASE("vdb: splat info lists the grids", "[vdb][cli]") {
    OPENVDB_OR_SKIP();
    SPARSE_DATA_OR_SKIP(data);
    const RunResult r =
        runProgram(SPLAT_EXE, {"info", (data / "grids.vdb").string(), "--grid", "temperature"});
    CHECK(r.status == 0);
    CHECK(r.out.find("OpenVDB:     3 grids") != std::string::npos);
    CHECK(r.out.find("'temperature' float: 120 active voxels, bbox (10, 20, 30)-(13, 24, 35), "
                     "background -1, voxel 0.25 x 0.25 x 0.25") != std::string::npos);
    CHECK(r.out.find("'velocity' vec3s: 1 active voxels") != std::string::npos);
    const RunResult e =
        runProgram(SPLAT_EXE, {"info", (data / "grids.vdb").string(), "--grid", "velocity"});
    CHECK(e.status == 1);
    REQUIRE(e.errLines().size() == 1);
    CHECK(e.errLines()[0].rfind("splat: error: ", 0) == 0);
}
