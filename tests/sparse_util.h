#pragma once
// The test data of the OpenVDB and OME-Zarr readers, written once per test process by
// tests/sparse/make_sparse_data.py with the formats' own Python libraries (python3-openvdb,
// python3-zarr, nibabel). sparseData() is empty (and the caller skips with a message) when
// one of them is missing.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include "cli_util.h"
#include "splat/bricks.h"
#include "splat/volume_io.h"

namespace splat::test {

/// Removes this process's copy of the data when the process ends.
struct SparseDataDir {
    std::optional<std::filesystem::path> path;
    ~SparseDataDir() {
        std::error_code ec;
        if (path) std::filesystem::remove_all(*path, ec);
    }
};

/// The data, written by this process into a folder of its own (ctest runs test cases as
/// concurrent processes, which must not write one folder at the same time; writing it takes
/// under a second).
inline std::optional<std::filesystem::path> sparseData() {
    static std::once_flag once;
    static SparseDataDir owned;
    static std::optional<std::filesystem::path> dir;
    std::call_once(once, [] {
        const std::filesystem::path out =
            testTmpDir("sparse_data_" + std::to_string(long(getpid())));
        owned.path = out;
        const std::string cmd = std::string("/usr/bin/python3 ") + SPLAT_TEST_SOURCE_DIR +
                                "/sparse/make_sparse_data.py " + out.string();
        const int status = std::system(cmd.c_str());
        if (status == 0) dir = out;
    });
    return dir;
}

/// A file's geometry (volumeGeometry, no samples) is the loaded volume's, the file is read
/// brick by brick (`alone`), and the brick [lo, hi) read alone equals that crop of the whole
/// volume, sample for sample.
inline void checkBrickReadAlone(const std::string& spec, const LoadOptions& o,
                                const glm::ivec3& lo, const glm::ivec3& hiFromEnd) {
    const Volume whole = loadVolume(spec, o);
    bool alone = false;
    const Volume g = volumeGeometry(spec, o, &alone);
    CHECK(alone);
    CHECK(g.dims == whole.dims);
    CHECK(g.spacing == whole.spacing);
    CHECK(g.origin == whole.origin);
    CHECK(g.background == whole.background);
    CHECK(g.backgroundSource == whole.backgroundSource);
    const glm::ivec3 hi = whole.dims - hiFromEnd;
    const Volume b = loadVolumeBrick(spec, o, lo, hi);
    REQUIRE(b.dims == hi - lo);
    CHECK(b.origin == whole.world(glm::dvec3(lo)));
    std::size_t wrong = 0;
    for (int k = 0; k < b.dims.z; ++k)
        for (int j = 0; j < b.dims.y; ++j)
            for (int i = 0; i < b.dims.x; ++i)
                wrong += b.at(i, j, k) != whole.at(lo.x + i, lo.y + j, lo.z + k);
    CHECK(wrong == 0);
}

}  // namespace splat::test

/// Skips the rest of a test case (with a message) when the data cannot be written.
#define SPARSE_DATA_OR_SKIP(var)                                                          \
    const auto var##_dir = splat::test::sparseData();                                     \
    if (!var##_dir) {                                                                     \
        WARN(                                                                             \
            "python3-openvdb, python3-zarr or python3-nibabel missing (tools/setup.sh): " \
            "skipped");                                                                   \
        return;                                                                           \
    }                                                                                     \
    const std::filesystem::path var = *var##_dir
