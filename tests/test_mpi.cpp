// The `splat` program under mpirun (docs/parallel.md): frame-parallel
// sequences equal the one-process run bit for bit, bricked frames equal it within 1e-5 of
// the peak, a failing rank ends the job with one error. Hidden tag [.mpi]: registered with
// ctest only when splat is built with MPI (tests/CMakeLists.txt).
#if SPLAT_TEST_HAVE_MPI  // the whole file: splat built with MPI (SPLAT_MPI)
#include <catch2/catch.hpp>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "image_diff.h"
#include "mpi_util.h"
#include "splat/image_io.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

std::string bytesOf(const fs::path& p) { return readTextFile(p); }

void requireSameFiles(const fs::path& a, const fs::path& b) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(a)) names.push_back(e.path().filename().string());
    REQUIRE(!names.empty());
    for (const std::string& n : names) {
        INFO(n);
        REQUIRE(fs::exists(b / n));
        CHECK(bytesOf(a / n) == bytesOf(b / n));
    }
}

}  // namespace

/// Moves `from` (a file or folder) to `to`, replacing it.
void moveTo(const fs::path& from, const fs::path& to) {
    fs::remove_all(to);
    fs::rename(from, to);
}

/// A JSON document without its wall-time fields (ms_per_frame and keys ending in "_ms").
nlohmann::json withoutTimes(nlohmann::json j) {
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end();) {
            const std::string k = it.key();
            if (k == "ms_per_frame" || (k.size() >= 3 && k.substr(k.size() - 3) == "_ms"))
                it = j.erase(it);
            else
                *it = withoutTimes(*it), ++it;
        }
    } else if (j.is_array()) {
        for (auto& e : j) e = withoutTimes(e);
    }
    return j;
}

// The outputs name themselves in their metadata (the command line), so every run writes to
// the same paths and the one-process outputs are moved aside to compare.
TEST_CASE("mpi: rotate on 2 and 3 ranks writes the one-process frames, GIF and contact sheet",
          "[.mpi]") {
    const fs::path dir = testTmpDir("mpi_rotate");
    const fs::path out = dir / "out", gif = dir / "out.gif", sheet = dir / "sheet.png";
    const std::vector<std::string> args = {"rotate",      "synthetic:phantom:32",
                                           "--size",      "40x32",
                                           "--frames",    "7",
                                           "-q",          "-o",
                                           out.string(),  "--gif",
                                           gif.string(),  "--contact-sheet",
                                           sheet.string()};
    const RunResult one = runSplat(args);
    REQUIRE(one.status == 0);
    moveTo(out, dir / "one");
    moveTo(gif, dir / "one.gif");
    moveTo(sheet, dir / "one_sheet.png");
    auto requireSame = [&] {
        requireSameFiles(dir / "one", out);
        CHECK(bytesOf(dir / "one.gif") == bytesOf(gif));
        CHECK(bytesOf(dir / "one_sheet.png") == bytesOf(sheet));
    };
    for (int n : {2, 3}) {
        fs::remove_all(out);
        const RunResult r = mpirunSplat(n, args);
        INFO(n << " ranks: " << r.err);
        REQUIRE(r.status == 0);
        CHECK(r.errLines().empty());
        requireSame();
    }
    // --resume across rank counts: frames of the 3-rank run, two removed, finished on 2.
    fs::remove(out / "frame_0001.png");
    fs::remove(out / "frame_0005.png");
    auto resumed = args;
    resumed.push_back("--resume");
    const RunResult r = mpirunSplat(2, resumed);
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("wrote 2 frames") != std::string::npos);
    requireSame();
    // More ranks than frames.
    const std::vector<std::string> two = {
        "rotate", "synthetic:blob:16",   "--size", "24x24", "--frames", "2", "-q",
        "-o",     (dir / "two").string()};
    REQUIRE(runSplat(two).status == 0);
    moveTo(dir / "two", dir / "two_one");
    REQUIRE(mpirunSplat(3, two).status == 0);
    requireSameFiles(dir / "two_one", dir / "two");
}

TEST_CASE("mpi: popping on 3 ranks finds what one process finds", "[.mpi]") {
    const fs::path dir = testTmpDir("mpi_popping");
    const std::vector<std::string> args = {"popping",   "synthetic:phantom:24",
                                           "--size",    "32x32",
                                           "--from",    "40",
                                           "--to",      "50",
                                           "--step",    "1",
                                           "--refine",  "3",
                                           "--no-flip", "-q",
                                           "--report",  (dir / "pop").string()};
    const RunResult one = runSplat(args);
    REQUIRE(one.status == 0);
    moveTo(dir / "pop", dir / "pop_one");
    const RunResult three = mpirunSplat(3, args);
    INFO(three.err);
    REQUIRE(three.status == 0);
    CHECK(bytesOf(dir / "pop_one" / "metrics.csv") == bytesOf(dir / "pop" / "metrics.csv"));
    const auto summary = [](const fs::path& p) {
        return withoutTimes(nlohmann::json::parse(readTextFile(p)));
    };
    CHECK(summary(dir / "pop_one" / "summary.json") == summary(dir / "pop" / "summary.json"));
    // The printed table without its ms/frame column, and the events.
    auto findings = [](const std::string& out) {
        std::string kept;
        std::istringstream in(out);
        for (std::string line; std::getline(in, line);) {
            if (line.rfind("wrote ", 0) == 0) continue;
            const auto last = line.find_last_of(' ');
            const bool row = line.rfind("event", 0) != 0 && line.rfind("predicted", 0) != 0;
            std::string k = row && last != std::string::npos ? line.substr(0, last) : line;
            k.erase(k.find_last_not_of(' ') + 1);  // the time column's width varies
            kept += k + "\n";
        }
        return kept;
    };
    CHECK(findings(one.out) == findings(three.out));
}

TEST_CASE("mpi: a bricked render on 2 and 3 ranks matches one process within 1e-5 of the peak",
          "[.mpi]") {
    const fs::path dir = testTmpDir("mpi_bricks");
    for (const std::string mode : {"dvr", "mip", "xray"}) {
        auto args = [&](const std::string& out) {
            return std::vector<std::string>{"render",
                                            "synthetic:phantom:27",
                                            "--renderer",
                                            "reference",
                                            "--mode",
                                            mode,
                                            "--size",
                                            "36x30",
                                            "--azimuth",
                                            "25",
                                            "--elevation",
                                            "15",
                                            "--ref-tolerance",
                                            "1e-7",
                                            "-o",
                                            (dir / out).string()};
        };
        REQUIRE(runSplat(args(mode + "_one.exr")).status == 0);
        const Image one = readImage((dir / (mode + "_one.exr")).string());
        for (int n : {2, 3}) {
            const std::string out = mode + "_np" + std::to_string(n) + ".exr";
            const RunResult r = mpirunSplat(n, args(out));
            INFO(mode << " on " << n << " ranks: " << r.err);
            REQUIRE(r.status == 0);
            CHECK(maxDiff(one, readImage((dir / out).string())) <= 1e-5f * peakOf(one));
        }
    }
    // The axis-aligned splatter is exact in bricks too (no early termination: a bricked ray's
    // opacity is not known within one brick).
    for (const std::string mode : {"dvr", "xray"}) {
        const std::vector<std::string> args = {"render",
                                               "synthetic:phantom:27",
                                               "--renderer",
                                               "axis",
                                               "--mode",
                                               mode,
                                               "--size",
                                               "36x30",
                                               "--azimuth",
                                               "25",
                                               "--early-termination",
                                               "0",
                                               "-o",
                                               (dir / ("axis_" + mode + ".exr")).string()};
        REQUIRE(runSplat(args).status == 0);
        const Image one = readImage((dir / ("axis_" + mode + ".exr")).string());
        const RunResult r = mpirunSplat(3, args);
        INFO(r.err);
        REQUIRE(r.status == 0);
        CHECK(maxDiff(one, readImage((dir / ("axis_" + mode + ".exr")).string())) <=
              1e-5f * peakOf(one));
    }
    // Uneven: odd dimensions, 5 bricks (not a power of 2) on 3 ranks, and more ranks than
    // bricks.
    auto args = [&](const std::string& out, const std::string& bricks) {
        return std::vector<std::string>{"render",
                                        "synthetic:blob:19",
                                        "--renderer",
                                        "reference",
                                        "--size",
                                        "28x28",
                                        "--azimuth",
                                        "60",
                                        "--ref-tolerance",
                                        "1e-7",
                                        "--bricks",
                                        bricks,
                                        "-o",
                                        (dir / out).string()};
    };
    REQUIRE(runSplat(args("blob_one.exr", "0")).status == 0);
    const Image one = readImage((dir / "blob_one.exr").string());
    for (const auto& [n, bricks] : std::vector<std::pair<int, std::string>>{{3, "5"}, {3, "2"}}) {
        const std::string out = "blob_" + std::to_string(n) + "_" + bricks + ".exr";
        const RunResult r = mpirunSplat(n, args(out, bricks));
        INFO(r.err);
        REQUIRE(r.status == 0);
        CHECK(maxDiff(one, readImage((dir / out).string())) <= 1e-5f * peakOf(one));
    }
}

TEST_CASE("mpi: a failing rank ends the job with one error on rank 0, no output, no hang",
          "[.mpi]") {
    const fs::path dir = testTmpDir("mpi_fail");
    // A raw file of 6x5x30 samples missing its last 5 slices: 3 bricks split z at 10 and
    // 20 (ghost layers 3), so only rank 2's brick (slices 17..29) reaches past the end.
    const fs::path raw = dir / "vol_6x5x30_uint8.raw";
    {
        std::ofstream out(raw, std::ios::binary);
        for (int n = 0; n < 6 * 5 * 25; ++n) out.put(char(n % 200));
    }
    const fs::path png = dir / "out.png";
    const RunResult r = mpirunSplat(3, {"render", raw.string(), "--background-value", "0", "--size",
                                   "24x24", "-o", png.string()});
    INFO(r.err);
    CHECK(r.status != 0);
    CHECK(r.status != 137);  // not killed by the timeout
    int errors = 0;
    for (const std::string& line : r.errLines())
        if (line.rfind("splat: error: ", 0) == 0) {
            ++errors;
            CHECK(line.find("rank 2 of 3") != std::string::npos);
            CHECK(line.find("truncated data") != std::string::npos);
        }
    CHECK(errors == 1);
    CHECK(!fs::exists(png));
    // A bad option fails on every rank alike: one error line, usage status.
    const RunResult u =
        mpirunSplat(2, {"rotate", "synthetic:blob:8", "--frames", "0", "-o", (dir / "never").string()});
    CHECK(u.status != 0);
    int usage = 0;
    for (const std::string& line : u.errLines()) usage += line.rfind("splat: error: ", 0) == 0;
    CHECK(usage == 1);
    CHECK(!fs::exists(dir / "never"));
}

#endif  // SPLAT_TEST_HAVE_MPI
