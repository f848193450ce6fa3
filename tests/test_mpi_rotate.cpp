// Bricked sequences under mpirun (docs/parallel.md): `mpirun -np 2
// splat rotate --bricks 3` (an uneven split, K not a multiple of the ranks) writes the frames
// of the one-process `splat rotate` within 1e-5 of the peak, exact sheets included; a brick
// that cannot be read ends the job with one error on rank 0 and no frame.
// Hidden tag [.mpi], run by the ctest test mpi.ranks when splat is built with MPI.
#if SPLAT_TEST_HAVE_MPI
#include <catch2/catch.hpp>
#include <cstdlib>
#include <fstream>

#include "cli_util.h"
#include "image_diff.h"
#include "mpi_util.h"
#include "splat/image_io.h"
#include "splat/synthetic.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

TEST_CASE("mpi: rotate --bricks on 2 ranks writes the one-process frames", "[.mpi]") {
    const fs::path dir = testTmpDir("mpi_rotate");
    fs::remove_all(dir);
    for (const std::string renderer : {"reference", "axis", "sheet"}) {
        auto args = [&](const std::string& out) {
            return std::vector<std::string>{"rotate",
                                            "synthetic:phantom:23",
                                            "--renderer",
                                            renderer,
                                            "--size",
                                            "34x30",
                                            "--frames",
                                            "3",
                                            "--format",
                                            "exr",
                                            "--early-termination",
                                            "0",
                                            "--ref-tolerance",
                                            "1e-7",
                                            "-q",
                                            "-o",
                                            (dir / (renderer + out)).string()};
        };
        REQUIRE(runSplat(args("_one")).status == 0);
        auto a = args("_np2");
        a.insert(a.end(), {"--bricks", "3"});
        const RunResult r = mpirunSplat(2, a);
        INFO(r.out << r.err);
        REQUIRE(r.status == 0);
        for (int f = 0; f < 3; ++f) {
            char name[32];
            std::snprintf(name, sizeof name, "frame_%04d.exr", f);
            const Image one = readImage((dir / (renderer + "_one") / name).string());
            const Image two = readImage((dir / (renderer + "_np2") / name).string());
            INFO(renderer << " frame " << f);
            CHECK(peakOf(one) > 0.05f);
            CHECK(maxDiff(one, two) <= 1e-5f * peakOf(one));
        }
    }
    // A file too short for its header: rank 1's brick is beyond its end. One error, exit 1,
    // no frame written.
    const Volume v = makeSynthetic("phantom", 20);
    const std::string data(reinterpret_cast<const char*>(v.data.data()),
                           v.data.size() * sizeof(float) / 2);
    std::ofstream(dir / "short.nrrd", std::ios::binary)
        << "NRRD0004\ntype: float\ndimension: 3\nsizes: 20 20 20\nendian: little\n"
           "encoding: raw\n\n"
        << data;
    const RunResult bad = mpirunSplat(
        2, {"rotate", (dir / "short.nrrd").string(), "--bricks", "2", "--frames", "2", "--size",
            "16x16", "--background-value", "0", "-q", "-o", (dir / "short").string()});
    CHECK(bad.status == 1);
    CHECK(bad.err.find("splat: error:") != std::string::npos);
    CHECK(!fs::exists(dir / "short" / "frame_0000.png"));
}
#endif
