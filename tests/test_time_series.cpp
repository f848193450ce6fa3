// Time series: a 4D NIfTI written by nibabel (the oracle: its own array, step by step), a 4D
// NRRD with a time axis (raw and gzip), a folder of 3D files; a step past the last is an
// OptionError, and an input without a time axis holds only step 0. Backgrounds are not 0.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>

#include "deflate_util.h"
#include "splat/error.h"
#include "splat/volume_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

/// f(x, y, z, t) of the test series: distinct in every voxel and step, background 100.
double seriesValue(int x, int y, int z, int t) { return 100 + x + 10 * y + 100 * z + 1000 * t; }

/// Runs a nibabel script (Debian's python3); false when nibabel is missing.
bool runPython(const std::string& script, const fs::path& dir) {
    const fs::path file = dir / "write.py";
    writeBytes(file, script);
    return std::system(("/usr/bin/python3 " + file.string() + " > /dev/null 2>&1").c_str()) == 0;
}

LoadOptions at(int t) {
    LoadOptions o;
    o.time = t;
    return o;
}

void checkStep(const Volume& v, int t, glm::ivec3 dims) {
    REQUIRE(v.dims == dims);
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x)
                REQUIRE(v.at(x, y, z) == float(seriesValue(x, y, z, t)));
}

}  // namespace

TEST_CASE("time series: 4D NIfTI written by nibabel, each step as nibabel holds it",
          "[volume][time]") {
    const fs::path dir = testTmpDir("time_nifti");
    // x fastest in the file; nibabel indexes [x, y, z, t]. A scale and a translation in the
    // affine, so every step has the same geometry.
    const std::string script =
        "import numpy as np, nibabel as nib\n"
        "x, y, z, t = np.meshgrid(np.arange(5), np.arange(4), np.arange(3), np.arange(6),\n"
        "                         indexing='ij')\n"
        "a = (100 + x + 10 * y + 100 * z + 1000 * t).astype(np.float32)\n"
        "aff = np.diag([0.5, 2.0, 1.5, 1.0]); aff[:3, 3] = [10, -4, 7]\n"
        "for name in ['s.nii', 's.nii.gz']:\n"
        "    nib.save(nib.Nifti1Image(a, aff), '" +
        dir.string() +
        "/' + name)\n"
        "np.testing.assert_array_equal(np.asarray(nib.load('" +
        dir.string() + "/s.nii').dataobj)[..., 4], a[..., 4])\n";
    if (!runPython(script, dir)) {
        WARN("skipped: python3-nibabel is missing (tools/setup.sh)");
        return;
    }
    for (const char* file : {"s.nii", "s.nii.gz"}) {
        INFO(file);
        const std::string path = (dir / file).string();
        for (int t : {0, 1, 5}) {
            const Volume v = loadVolume(path, at(t));
            checkStep(v, t, {5, 4, 3});
            CHECK(v.spacing == glm::dvec3(0.5, 2.0, 1.5));
            CHECK(v.origin == glm::dvec3(10, -4, 7));
            CHECK_THAT(v.source, Catch::Contains("time step " + std::to_string(t) + " of 6"));
            CHECK(v.note.find("4D file") == std::string::npos);
        }
        // No step asked for: the first, with the note.
        const Volume first = loadVolume(path);
        checkStep(first, 0, {5, 4, 3});
        CHECK_THAT(first.note, Catch::Contains("only the first of 6 volumes"));
        // Past the last step: an OptionError naming the range.
        CHECK_THROWS_MATCHES(loadVolume(path, at(6)), OptionError,
                             Catch::Message(path + ": time step 6 is out of range: it holds "
                                                   "time steps 0 to 5"));
    }
}

TEST_CASE("time series: 4D NRRD along its last axis, raw and gzip", "[volume][time]") {
    const fs::path dir = testTmpDir("time_nrrd");
    std::vector<double> values;
    for (int t = 0; t < 3; ++t)
        for (int z = 0; z < 2; ++z)
            for (int y = 0; y < 3; ++y)
                for (int x = 0; x < 4; ++x) values.push_back(seriesValue(x, y, z, t));
    const std::string head =
        "NRRD0004\ntype: float\ndimension: 4\nsizes: 4 3 2 3\nspace: right-anterior-superior\n"
        "space directions: (1,0,0) (0,2,0) (0,0,3) none\nkinds: domain domain domain time\n"
        "endian: little\n";
    writeBytes(dir / "raw.nrrd", head + "encoding: raw\n\n" + samples<float>(values));
    writeBytes(dir / "gz.nrrd",
               head + "encoding: gzip\n\n" + deflateBytes(samples<float>(values), true));
    writeBytes(
        dir / "text.nrrd", head + "encoding: text\n\n" + [&] {
            std::string s;
            for (double v : values) s += std::to_string(int(v)) + " ";
            return s;
        }());
    for (const char* file : {"raw.nrrd", "gz.nrrd", "text.nrrd"}) {
        INFO(file);
        const std::string path = (dir / file).string();
        for (int t = 0; t < 3; ++t) {
            const Volume v = loadVolume(path, at(t));
            checkStep(v, t, {4, 3, 2});
            CHECK(v.spacing == glm::dvec3(1, 2, 3));
        }
        CHECK_THAT(loadVolume(path).note, Catch::Contains("only the first of 3 time steps"));
        CHECK_THROWS_AS(loadVolume(path, at(3)), OptionError);
    }
    // A 4D NRRD whose last axis is a vector, not time, is refused by name.
    writeBytes(dir / "list.nrrd",
               "NRRD0004\ntype: float\ndimension: 4\nsizes: 4 3 2 3\nkinds: domain domain "
               "domain vector\nencoding: raw\nendian: little\n\n" +
                   samples<float>(values));
    CHECK_THAT(errorOf([&] { loadVolume((dir / "list.nrrd").string()); }),
               Catch::Contains("last axis is of kind 'vector'"));
}

TEST_CASE("time series: a folder of 3D files in natural order; inputs without a time axis",
          "[volume][time]") {
    const fs::path dir = testTmpDir("time_folder");
    fs::create_directories(dir / "series");
    // step_2 sorts before step_10 (natural order); each file one step.
    int step = 0;
    for (const char* name : {"step_1.nrrd", "step_2.nrrd", "step_10.nrrd"}) {
        std::vector<double> values;
        for (int z = 0; z < 2; ++z)
            for (int y = 0; y < 2; ++y)
                for (int x = 0; x < 3; ++x) values.push_back(seriesValue(x, y, z, step));
        writeBytes(dir / "series" / name,
                   "NRRD0004\ntype: float\ndimension: 3\nsizes: 3 2 2\nendian: little\n"
                   "encoding: raw\n\n" +
                       samples<float>(values));
        ++step;
    }
    const std::string folder = (dir / "series").string();
    for (int t = 0; t < 3; ++t) {
        const Volume v = loadVolume(folder, at(t));
        checkStep(v, t, {3, 2, 2});
        CHECK_THAT(v.source, Catch::Contains("time step " + std::to_string(t) + " of 3"));
    }
    CHECK_THAT(loadVolume(folder).note, Catch::Contains("folder of 3 volume files"));
    CHECK_THROWS_AS(loadVolume(folder, at(3)), OptionError);
    // Without a time axis there is the one step 0.
    const std::string file = (dir / "series" / "step_1.nrrd").string();
    CHECK(loadVolume(file, at(0)).dims == glm::ivec3(3, 2, 2));
    CHECK_THROWS_MATCHES(loadVolume(file, at(1)), OptionError,
                         Catch::Message(file + ": time step 1 is out of range: it holds one "
                                               "volume (time step 0)"));
    CHECK_THROWS_AS(loadVolume("synthetic:blob:8", at(1)), OptionError);
    CHECK(loadVolume("synthetic:blob:8", at(0)).dims == glm::ivec3(8));
}
