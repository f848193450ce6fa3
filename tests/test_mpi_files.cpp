// Bricks read from files under mpirun, and the number of bricks chosen from --rank-memory
// (docs/parallel.md): a NRRD whose file axes are permuted and flipped
// against the world, raw-stored and gzip-compressed, with a CT background (-1000), renders on
// 2 and 3 ranks as on one process (within 1e-5 of the peak) without --background-value.
// Hidden tag [.mpi], run by the ctest test mpi.ranks when splat is built with MPI.
#if SPLAT_TEST_HAVE_MPI
#include <catch2/catch.hpp>
#include <cstdlib>
#include <fstream>

#include "cli_util.h"
#include "image_diff.h"
#include "mpi_util.h"
#include "deflate_util.h"
#include "footprint/kernel.h"
#include "splat/brick_budget.h"
#include "splat/bricks.h"
#include "splat/image_io.h"
#include "splat/synthetic.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

}  // namespace

TEST_CASE("mpi: bricks read from NRRD files, K chosen from --rank-memory", "[.mpi]") {
    const fs::path dir = testTmpDir("mpi_files");
    // The HU phantom (air -1000) as float samples, file axis 0 along -y, 1 along +z, 2 along -x.
    const Volume v = makeSynthetic("phantom", 29);
    std::string data(reinterpret_cast<const char*>(v.data.data()), v.data.size() * sizeof(float));
    const std::string header =
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 29 29 29\nendian: little\n"
        "space: RAS\nspace directions: (0,-1.5,0) (0,0,2) (-1,0,0)\n";
    {
        std::ofstream(dir / "raw.nrrd", std::ios::binary) << header << "encoding: raw\n\n" << data;
        std::ofstream(dir / "gz.nrrd", std::ios::binary) << header << "encoding: gzip\n\n"
                                                         << deflateBytes(data, true);
    }
    for (const std::string file : {"raw.nrrd", "gz.nrrd"}) {
        const std::string spec = (dir / file).string();
        auto args = [&](const std::string& out, const std::string& budget) {
            std::vector<std::string> a = {
                "render",          spec,        "--renderer", "reference",         "--size",
                "32x28",           "--azimuth", "35",         "--elevation",       "20",
                "--ref-tolerance", "1e-7",      "-o",         (dir / out).string()};
            if (!budget.empty()) a.insert(a.end(), {"--rank-memory", budget});
            return a;
        };
        REQUIRE(runSplat(args(file + "_one.exr", "")).status == 0);
        const Image one = readImage((dir / (file + "_one.exr")).string());
        // A budget a little above the process itself (150 MiB + 184 KB): on 2 ranks, more bricks
        // than ranks (6).
        for (int n : {2, 3}) {
            const std::string out = file + "_np" + std::to_string(n) + ".exr";
            const RunResult r = mpirunSplat(n, args(out, "150.18"));
            INFO(file << " on " << n << " ranks: " << r.err << r.out);
            REQUIRE(r.status == 0);
            CHECK(maxDiff(one, readImage((dir / out).string())) <= 1e-5f * peakOf(one));
            BrickBudget b;
            b.rankBytes = std::uint64_t(150.18 * 1048576.0);
            b.ranks = n;
            b.width = 32;
            b.height = 28;
            b.ghost = ghostLayers(footprint::Kernel::fromName("gaussian").radius(),
                                  glm::dvec3(1, 1.5, 2));
            const BrickChoice c = chooseBricks(glm::ivec3(29, 29, 29), b);
            CHECK(c.bricks % n == 0);
            if (n == 2) CHECK(c.bricks > n);  // the whole volume and 2 bricks exceed it
            CHECK(r.out.find("bricks: " + std::to_string(c.bricks) + " (") != std::string::npos);
        }
    }
}

#endif  // SPLAT_TEST_HAVE_MPI
