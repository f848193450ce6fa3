// The library's writers under faults: writeImage, writeTextAtomic and the study
// report throw splat::Error naming the file and the OS error, and leave the previous file
// untouched and no temporary behind. The failing write is made by RLIMIT_FSIZE with SIGXFSZ
// ignored (write(2) then fails with EFBIG part way through the file); the command-line
// cases (full tmpfs, read-only folder, kills) are in tests/faults/fault_injection.py.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

#include "cli_util.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/study.h"
#include "splat/volume.h"
#include "splat/volume_io.h"

namespace fs = std::filesystem;
using splat::test::testTmpDir;

namespace {

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

void put(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

/// Files may grow to `bytes` while it lives (SIGXFSZ ignored: writes fail with EFBIG).
class FileSizeLimit {
  public:
    explicit FileSizeLimit(rlim_t bytes) {
        old_ = std::signal(SIGXFSZ, SIG_IGN);
        getrlimit(RLIMIT_FSIZE, &saved_);
        rlimit r = saved_;
        r.rlim_cur = bytes;
        setrlimit(RLIMIT_FSIZE, &r);
    }
    ~FileSizeLimit() {
        setrlimit(RLIMIT_FSIZE, &saved_);
        std::signal(SIGXFSZ, old_);
    }

  private:
    rlimit saved_{};
    void (*old_)(int) = nullptr;
};

std::size_t temporariesIn(const fs::path& dir) {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir))
        n += splat::isAtomicTemporary(e.path().filename().string());
    return n;
}

splat::Image gradient(int w, int h) {
    splat::Image im(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            im.at(x, y) = glm::vec4(float((x * 7919 + y * 104729) % 251) / 250.0f,
                                    float(x) / float(w), float(y) / float(h), 1.0f);
    return im;
}

}  // namespace

TEST_CASE("writeImage on a failing write throws, names the file and keeps the previous one",
          "[faults]") {
    const fs::path dir = testTmpDir("faults_image");
    for (const char* ext : {".png", ".exr", ".tif"}) {
        const fs::path file = dir / (std::string("picture") + ext);
        splat::writeImage(file.string(), gradient(8, 8));
        const std::string before = slurp(file);
        REQUIRE(!before.empty());
        std::string message;
        {
            // Every one of these encodings of a 200 x 200 noisy image exceeds 16 KiB.
            FileSizeLimit limit(16384);
            try {
                splat::writeImage(file.string(), gradient(200, 200));
            } catch (const splat::Error& e) {
                message = e.what();
            }
        }
        INFO(ext << ": " << message);
        CHECK(message.find(file.string()) != std::string::npos);
        CHECK(message.find("File too large") != std::string::npos);
        CHECK(slurp(file) == before);
        CHECK(temporariesIn(dir) == 0);
        // With room, the same call replaces the file with one that reads back whole.
        splat::writeImage(file.string(), gradient(200, 200));
        CHECK(splat::readImage(file.string()).width == 200);
    }
}

TEST_CASE("writeTextAtomic: a failing write keeps the previous file; a missing folder is named",
          "[faults]") {
    const fs::path dir = testTmpDir("faults_text");
    const fs::path file = dir / "notes.json";
    put(file, "previous\n");
    const std::string big(10000, 'x');
    {
        FileSizeLimit limit(4096);
        CHECK_THROWS_WITH(splat::writeTextAtomic(file, big),
                          Catch::Contains(file.string()) && Catch::Contains("File too large"));
        // A file under the limit still goes through whole.
        splat::writeTextAtomic(dir / "small.txt", "small\n");
    }
    CHECK(slurp(file) == "previous\n");
    CHECK(slurp(dir / "small.txt") == "small\n");
    CHECK(temporariesIn(dir) == 0);
    CHECK_THROWS_WITH(splat::writeTextAtomic(dir / "gone" / "x.txt", "x"),
                      Catch::Contains("does not exist"));
}

TEST_CASE("AtomicFile refuses an external writer's missing or empty file", "[faults]") {
    const fs::path dir = testTmpDir("faults_external");
    const fs::path file = dir / "video.mp4";
    put(file, "previous video");
    {
        splat::AtomicFile out(file);  // the writer wrote nothing at all
        CHECK_THROWS_WITH(out.commit(), Catch::Contains("nothing was written"));
    }
    {
        splat::AtomicFile out(file);
        put(out.temporary(), "");  // the writer created the file and failed silently
        CHECK_THROWS_WITH(out.commit(), Catch::Contains("empty file"));
    }
    {
        splat::AtomicFile out(file);
        put(out.temporary(), "new video");
        out.commit();
    }
    CHECK(slurp(file) == "new video");
    CHECK(temporariesIn(dir) == 0);
}

TEST_CASE("removeStaleTemporaries removes a dead process's temporaries only", "[faults]") {
    const fs::path dir = testTmpDir("faults_stale");
    const pid_t child = fork();
    if (child == 0) _exit(0);
    REQUIRE(child > 0);
    waitpid(child, nullptr, 0);  // now a pid that no longer runs
    const fs::path dead = dir / (".frame.tmp" + std::to_string(child) + "-0.png");
    const fs::path alive = dir / (".frame.tmp" + std::to_string(getppid()) + "-0.png");
    const fs::path mine = dir / (".frame.tmp" + std::to_string(getpid()) + "-3.png");
    for (const auto& p : {dead, alive, mine, dir / "frame.png"}) put(p, "x");
    CHECK(splat::isAtomicTemporary(dead.filename().string()));
    CHECK_FALSE(splat::isAtomicTemporary("frame.png"));
    CHECK(splat::removeStaleTemporaries(dir) == 1);
    CHECK_FALSE(fs::exists(dead));
    CHECK(fs::exists(alive));
    CHECK(fs::exists(mine));
    CHECK(fs::exists(dir / "frame.png"));
}

TEST_CASE("writeStudyReport on a failing write keeps the whole previous report", "[faults]") {
    const fs::path dir = testTmpDir("faults_study");
    splat::StudyResult r;
    r.volume = "test";
    r.options.sweeps = {{"slab", {"1", "0.5"}}};
    for (int i = 0; i < 2; ++i) {
        splat::StudyPoint p;
        p.knobs = {{"slab", i ? "0.5" : "1"}};
        p.msMedian = 10.0 * (i + 1);
        p.rmse = 0.1 / (i + 1);
        r.points.push_back(p);
    }
    splat::markPareto(r.points);
    const char* files[] = {"study.csv", "study.json", "pareto.svg", "pareto.png"};
    for (const char* f : files) put(dir / f, std::string("previous ") + f);
    {
        FileSizeLimit limit(1024);  // the CSV fits, the PNG does not
        CHECK_THROWS_WITH(splat::writeStudyReport(r, dir.string(), "splat study"),
                          Catch::Contains("File too large"));
    }
    for (const char* f : files) CHECK(slurp(dir / f) == std::string("previous ") + f);
    CHECK(temporariesIn(dir) == 0);
    splat::writeStudyReport(r, dir.string(), "splat study");
    CHECK(slurp(dir / "study.csv").rfind("slab,ms_median", 0) == 0);
    CHECK(splat::readImage((dir / "pareto.png").string()).width > 100);
}

TEST_CASE("saveNifti on a failing write throws and keeps the previous volume", "[faults]") {
    const fs::path dir = testTmpDir("faults_nifti");
    splat::Volume small;
    small.dims = {4, 4, 4};
    small.data.assign(64, 1.0f);
    for (const char* name : {"v.nii", "v.nii.gz"}) {
        const fs::path file = dir / name;
        splat::saveNifti(file.string(), small);
        const std::string before = slurp(file);
        splat::Volume big;
        big.dims = {40, 40, 40};
        big.data.resize(64000);
        std::mt19937 random(7);  // noise: no compression brings it under the limit
        for (float& d : big.data) d = std::uniform_real_distribution<float>(0, 1)(random);
        {
            FileSizeLimit limit(8192);
            CHECK_THROWS_WITH(splat::saveNifti(file.string(), big), Catch::Contains(file.string()));
        }
        CHECK(slurp(file) == before);
        CHECK(temporariesIn(dir) == 0);
    }
}

TEST_CASE("a temporary that disappears before the rename is an error, not a file", "[faults]") {
    const fs::path dir = testTmpDir("faults_vanish");
    const fs::path file = dir / "table.csv";
    put(file, "previous\n");
    splat::AtomicFile out(file);
    out.write("a,b\n", 4);
    fs::remove(out.temporary());  // another program removes it while it is being written
    CHECK_THROWS_WITH(out.commit(), Catch::Contains(file.string()) &&
                                        Catch::Contains("No such file or directory"));
    CHECK(slurp(file) == "previous\n");
    // Its folder disappearing is named the same way.
    const fs::path gone = dir / "gone";
    fs::create_directories(gone);
    splat::AtomicFile lost(gone / "x.json");
    fs::remove_all(gone);
    CHECK_THROWS_WITH(lost.write("{}", 2), Catch::Contains("No such file or directory"));
}
