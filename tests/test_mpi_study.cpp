// `splat study` under mpirun (docs/parallel.md): the references are
// rendered across the ranks before anything is timed, the timed frames on rank 0 alone; every
// output but the wall times and memory figures equals the one-process run's. Hidden tag
// [.mpi]: run by mpi.ranks.
#if SPLAT_TEST_HAVE_MPI  // the whole file: splat built with MPI (SPLAT_MPI)
#include <catch2/catch.hpp>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "cli_util.h"
#include "mpi_util.h"
#include "splat/image_io.h"

using namespace splat::test;
namespace fs = std::filesystem;

namespace {

/// study.csv without the columns that time or weigh the run (and the Pareto mark, which
/// follows the times).
std::vector<std::vector<std::string>> untimedCsv(const fs::path& file) {
    std::istringstream in(readTextFile(file));
    std::vector<std::vector<std::string>> rows;
    std::vector<bool> keep;
    for (std::string line; std::getline(in, line);) {
        std::vector<std::string> cells, kept;
        std::stringstream ls(line);
        for (std::string c; std::getline(ls, c, ',');) cells.push_back(c);
        if (keep.empty())
            for (const std::string& c : cells)
                keep.push_back(c.rfind("ms_", 0) != 0 && c != "peak_mib" &&
                               c != "footprint_pixels_per_s" && c != "pareto");
        for (std::size_t i = 0; i < cells.size() && i < keep.size(); ++i)
            if (keep[i]) kept.push_back(cells[i]);
        rows.push_back(kept);
    }
    return rows;
}

}  // namespace

TEST_CASE("mpi: study on 2 ranks measures what one process measures", "[.mpi]") {
    const fs::path dir = testTmpDir("mpi_study");
    auto args = [&](const std::string& report) {
        return std::vector<std::string>{"study",     "synthetic:phantom:20",
                                        "--sweep",   "renderer=axis,sheet",
                                        "--sweep",   "size=24,32",
                                        "--views",   "0,40:20",
                                        "--repeats", "1",
                                        "--warmup",  "0",
                                        "--report",  (dir / report).string(),
                                        "--no-presets", "-q"};
    };
    fs::remove_all(dir / "one");
    fs::remove_all(dir / "np2");
    const RunResult one = runSplat(args("one"));
    INFO(one.err);
    REQUIRE(one.status == 0);
    const RunResult two = mpirunSplat(2, args("np2"));
    INFO(two.err);
    REQUIRE(two.status == 0);
    const auto a = untimedCsv(dir / "one" / "study.csv"), b = untimedCsv(dir / "np2" / "study.csv");
    REQUIRE(a.size() == 5);  // header and 2 renderers x 2 sizes
    CHECK(a == b);
    // The references, rendered on both ranks, have the one-process references' pixels bit for
    // bit.
    int references = 0;
    for (const auto& e : fs::directory_iterator(dir / "one" / "cache")) {
        INFO(e.path().filename());
        const fs::path other = dir / "np2" / "cache" / e.path().filename();
        REQUIRE(fs::exists(other));
        const splat::Image x = splat::readImage(e.path().string()),
                           y = splat::readImage(other.string());
        REQUIRE(x.pixels.size() == y.pixels.size());
        CHECK(std::memcmp(x.pixels.data(), y.pixels.data(), x.pixels.size() * sizeof x.pixels[0]) ==
              0);
        ++references;
    }
    CHECK(references == 4);  // 2 views x 2 sizes
}

#endif
