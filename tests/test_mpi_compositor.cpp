// The compositors of bricks under mpirun (splat/mpi/brick_group.h, docs/parallel.md): the sparse
// direct-send gives the one-process bricked frame bit for bit (the same blends in the same order;
// only the transparent pixels are left out of its messages), IceT (when splat is built with it) the
// same frame within float rounding, for every renderer that composites partial images, an empty
// brick included. Hidden tag [.mpi]: run by mpi.ranks. The usage errors of --compositor need no
// mpirun.
#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>

#include "cli_util.h"
#include "image_diff.h"
#include "mpi_util.h"
#include "splat/image_io.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

TEST_CASE("cli: --compositor takes direct or icet (when built with IceT) or auto", "[cli]") {
    const fs::path dir = testTmpDir("compositor_usage");
    auto render = [&](const std::string& compositor) {
        return runSplat({"render", "synthetic:blob:8", "--size", "8x8", "--bricks", "2",
                         "--compositor", compositor, "-o", (dir / "a.exr").string()});
    };
    const RunResult bad = render("radix-k");
    CHECK(bad.status == 2);
    CHECK(bad.err.find("splat: error: --compositor must be direct, icet or auto") !=
          std::string::npos);
    CHECK(render("direct").status == 0);
    CHECK(render("auto").status == 0);
#if SPLAT_TEST_HAVE_ICET
    CHECK(render("icet").status == 0);
#else
    const RunResult icet = render("icet");
    CHECK(icet.status == 2);
    CHECK(icet.err.find("splat: error: --compositor icet: this splat was built without IceT") !=
          std::string::npos);
    CHECK(!fs::exists(dir / "a.exr.tmp"));
#endif
}

#if SPLAT_TEST_HAVE_MPI  // the rest: splat built with MPI (SPLAT_MPI)

namespace {

bool sameBits(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height &&
           std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof a.pixels[0]) == 0;
}

}  // namespace

TEST_CASE("mpi: direct-send equals one process bit for bit and IceT within 1e-5 of the peak",
          "[.mpi]") {
    const fs::path dir = testTmpDir("mpi_compositor");
    // A volume whose first brick holds only background: 30x8x8 samples, zero for x < 20, a
    // ramp beyond. Three bricks split x at 10 and 20 (ghost layers 5), so brick 0 (samples
    // 0..14 loaded) has no splat and its partial image is transparent everywhere.
    const fs::path raw = dir / "half_30x8x8_uint8.raw";
    {
        std::ofstream out(raw, std::ios::binary);
        for (int z = 0; z < 8; ++z)
            for (int y = 0; y < 8; ++y)
                for (int x = 0; x < 30; ++x) out.put(char(x < 20 ? 0 : 60 + 10 * (x - 20)));
    }
    struct Case {
        std::string name, volume, renderer, mode;
        std::vector<std::string> extra;
    };
    const std::vector<Case> cases = {
        {"reference dvr", "synthetic:phantom:27", "reference", "dvr", {"--ref-tolerance", "1e-6"}},
        {"reference mip", "synthetic:phantom:27", "reference", "mip", {"--ref-tolerance", "1e-6"}},
        {"reference xray",
         "synthetic:phantom:27",
         "reference",
         "xray",
         {"--ref-tolerance", "1e-6"}},
        {"axis dvr", "synthetic:phantom:27", "axis", "dvr", {}},
        {"axis mip", "synthetic:phantom:27", "axis", "mip", {}},
        {"sheet fast dvr", "synthetic:phantom:27", "sheet", "dvr", {"--brick-composite", "fast"}},
        {"axis dvr, an empty brick",
         raw.string(),
         "axis",
         "dvr",
         {"--tf", "gray-ramp", "--background-value", "0"}},
        {"reference dvr, an empty brick",
         raw.string(),
         "reference",
         "dvr",
         {"--tf", "gray-ramp", "--background-value", "0", "--ref-tolerance", "1e-6"}},
    };
    for (const Case& c : cases) {
        for (int n : {2, 3}) {
            auto args = [&](const std::string& out, const std::string& compositor) {
                std::vector<std::string> a = {"render",
                                              c.volume,
                                              "--renderer",
                                              c.renderer,
                                              "--mode",
                                              c.mode,
                                              "--size",
                                              "36x30",
                                              "--azimuth",
                                              "25",
                                              "--elevation",
                                              "15",
                                              "--early-termination",
                                              "0",
                                              "--bricks",
                                              std::to_string(n),
                                              "-o",
                                              (dir / out).string()};
                a.insert(a.end(), c.extra.begin(), c.extra.end());
                if (!compositor.empty()) a.insert(a.end(), {"--compositor", compositor});
                return a;
            };
            INFO(c.name << ", " << n << " bricks on " << n << " ranks");
            REQUIRE(runSplat(args("one.exr", "")).status == 0);
            const Image one = readImage((dir / "one.exr").string());
            REQUIRE(peakOf(one) > 0);
            const RunResult direct = mpirunSplat(n, args("direct.exr", "direct"));
            INFO(direct.err);
            REQUIRE(direct.status == 0);
            CHECK(sameBits(one, readImage((dir / "direct.exr").string())));
#if SPLAT_TEST_HAVE_ICET
            const RunResult icet = mpirunSplat(n, args("icet.exr", "icet"));
            INFO(icet.err);
            REQUIRE(icet.status == 0);
            CHECK(maxDiff(one, readImage((dir / "icet.exr").string())) <= 1e-5f * peakOf(one));
#endif
        }
    }
}

#endif  // SPLAT_TEST_HAVE_MPI
