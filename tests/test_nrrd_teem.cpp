// NRRD as teem writes it: teem (Debian teem-apps, the format's reference
// implementation) writes one volume in every type, in all five encodings of the format
// (raw, gzip, bzip2, ascii, hex) and both byte orders; splat reads each voxel for voxel,
// and the world frame of every named space. Needs teem-unu (tools/setup.sh).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <type_traits>

#include "cli_util.h"
#include "splat/error.h"
#include "splat/volume_io.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

// Shell-quoted for std::system (our paths hold no single quote).
std::string quoted(const std::string& s) { return "'" + s + "'"; }

void unu(const std::string& args) {
    const std::string cmd = "teem-unu " + args + " 2>&1";
    INFO(cmd);
    REQUIRE(std::system(cmd.c_str()) == 0);
}

// Sample n of the test volume: the type's extremes first and last (a double's, beyond the
// range of float, as +-1e30).
template <class T>
T sample(std::size_t n, std::size_t count) {
    if constexpr (std::is_same_v<T, double>)
        if (n == 0 || n == count - 1) return n == 0 ? -1e30 : 1e30;
    if (n == 0) return std::numeric_limits<T>::lowest();
    if (n == count - 1) return std::numeric_limits<T>::max();
    if constexpr (std::is_floating_point_v<T>) return T(double(n) * 1.25 - 20.5);
    return T(std::int64_t(n * 37 % 251) - (std::is_signed_v<T> ? 100 : 0));
}

// Writes the test volume (5 x 4 x 3, little-endian raw) and returns the expected floats.
template <class T>
std::vector<float> writeRaw(const fs::path& p) {
    const std::size_t count = 5 * 4 * 3;
    std::vector<T> v(count);
    std::vector<float> expected(count);
    for (std::size_t n = 0; n < count; ++n) {
        v[n] = sample<T>(n, count);
        expected[n] = float(v[n]);
    }
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(v.data()), std::streamsize(count * sizeof(T)));
    return expected;
}

template <class T>
void everyEncoding(const std::string& type) {
    std::string folder = "nrrd_teem_" + type;
    std::replace(folder.begin(), folder.end(), ' ', '_');
    const fs::path dir = testTmpDir(folder);
    const std::vector<float> expected = writeRaw<T>(dir / "in.raw");
    const fs::path base = dir / "base.nrrd";
    unu("make -i " + quoted((dir / "in.raw").string()) + " -t " + quoted(type) +
        " -s 5 4 3 -e raw -en little -sp 1 1 1 -o " + quoted(base.string()));
    for (const char* encoding : {"raw", "gzip", "bzip2", "ascii", "hex"})
        for (const char* endian : {"big", "little"}) {
            // Text has no byte order; `unu save -e ascii -en big` byte-swaps the samples before
            // printing them (other numbers in the file), so ascii is checked little only.
            if (std::string(encoding) == "ascii" && std::string(endian) == "big") continue;
            const fs::path out = dir / (std::string(encoding) + "_" + endian + ".nrrd");
            unu(std::string("save -f nrrd -e ") + encoding + " -en " + endian + " -i " +
                quoted(base.string()) + " -o " + quoted(out.string()));
            INFO(type << " " << encoding << " " << endian);
            const Volume v = loadVolume(out.string());
            REQUIRE(v.dims == glm::ivec3(5, 4, 3));
            REQUIRE(v.data.size() == expected.size());
            std::size_t mismatches = 0;
            for (std::size_t n = 0; n < expected.size(); ++n)
                if (!(v.data[n] == expected[n])) ++mismatches;
            CHECK(mismatches == 0);
        }
}

}  // namespace

TEST_CASE("NRRD written by teem: every type, encoding and byte order", "[volume][nrrd][teem]") {
    everyEncoding<std::uint8_t>("uchar");
    everyEncoding<std::int8_t>("signed char");
    everyEncoding<std::uint16_t>("ushort");
    everyEncoding<std::int16_t>("short");
    everyEncoding<std::uint32_t>("uint");
    everyEncoding<std::int32_t>("int");
    everyEncoding<float>("float");
    everyEncoding<double>("double");
}

TEST_CASE("NRRD spaces: every named space in the RAS world frame", "[volume][nrrd][teem]") {
    const fs::path dir = testTmpDir("nrrd_spaces");
    writeRaw<std::int16_t>(dir / "in.raw");
    // Axes along +x, +y, +z of each space, origin (10, 20, -30) in it; expected RAS signs.
    struct Case {
        const char* space;
        glm::dvec3 toRas;
        int dims;
    };
    const Case cases[] = {{"RAS", {1, 1, 1}, 3},
                          {"LAS", {-1, 1, 1}, 3},
                          {"LPS", {-1, -1, 1}, 3},
                          {"RAST", {1, 1, 1}, 4},
                          {"LAST", {-1, 1, 1}, 4},
                          {"LPST", {-1, -1, 1}, 4},
                          {"scanner-xyz", {1, 1, 1}, 3},
                          {"3D-right-handed", {1, 1, 1}, 3},
                          {"3D-left-handed", {-1, 1, 1}, 3}};
    for (const Case& c : cases) {
        INFO(c.space);
        const std::string t = c.dims == 4 ? ",0" : "";
        const fs::path out = dir / (std::string(c.space) + ".nrrd");
        unu("make -i " + quoted((dir / "in.raw").string()) +
            " -t short -s 5 4 3 -e raw -en little -spc " + c.space + " -orig '(10,20,-30" + t +
            ")' -dirs '(2,0,0" + t + ") (0,3,0" + t + ") (0,0,4" + t + ")' -o " +
            quoted(out.string()));
        const Volume v = loadVolume(out.string());
        // Sample (i, j, k) of the file sits at space position (10 + 2i, 20 + 3j, -30 + 4k).
        const glm::dvec3 file(1, 2, 1);
        glm::dvec3 expected = c.toRas * (glm::dvec3(10, 20, -30) + glm::dvec3(2, 3, 4) * file);
        // Find that file sample in splat's (flipped) grid: value equality on a distinct sample.
        const std::size_t n = (1 * 4 + 2) * 5 + 1;
        const float value = float(sample<std::int16_t>(n, 60));
        int found = 0;
        for (int k = 0; k < v.dims.z; ++k)
            for (int j = 0; j < v.dims.y; ++j)
                for (int i = 0; i < v.dims.x; ++i)
                    if (v.at(i, j, k) == value) {
                        const glm::dvec3 w = v.worldPosition(glm::dvec3(i, j, k));
                        CHECK(glm::length(w - expected) < 1e-9);
                        ++found;
                    }
        CHECK(found == 1);
        CHECK_FALSE(v.rotated());
    }
}

TEST_CASE("NRRD hex and bzip2: damaged data is one clear error", "[volume][nrrd][hostile]") {
    const fs::path dir = testTmpDir("nrrd_damaged");
    const std::string head =
        "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 1\nendian: big\nencoding: ";
    auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir / name, std::ios::binary) << text;
        return (dir / name).string();
    };
    auto error = [](const std::string& p) {
        try {
            loadVolume(p);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(loaded)");
    };
    const Volume ok = loadVolume(write("ok.nrrd", head + "hex\n\n0001 00ff\nFF00 7fff\n"));
    CHECK(ok.data == std::vector<float>{1, 255, -256, 32767});
    CHECK_THAT(error(write("short.nrrd", head + "hex\n\n0001 00ff ff00\n")),
               Catch::Contains("truncated data"));
    CHECK_THAT(error(write("odd.nrrd", head + "hex\n\n0001 00ff ff00 7ff\n")),
               Catch::Contains("splits a byte"));
    CHECK_THAT(error(write("bad.nrrd", head + "hex\n\n0001 00fg ff00 7fff\n")),
               Catch::Contains("not a hex digit"));
    CHECK_THAT(error(write("long.nrrd", head + "hex\n\n0001 00ff ff00 7fff 0000\n")),
               Catch::Contains("more than the 8 bytes"));
    CHECK_THAT(error(write("bz.nrrd", head + "bzip2\n\nBZh91AY&SY garbage")),
               Catch::Contains("corrupt bzip2 data"));
    const std::string spaced = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 1 1\nencoding: raw\n";
    CHECK_THAT(error(write("sp1.nrrd", spaced + "space: left-posterior-inferior\n"
                                                "space directions: (1,0,0) (0,1,0) (0,0,1)\n\nab")),
               Catch::Contains("unknown NRRD space 'left-posterior-inferior'"));
    CHECK_THAT(
        error(write("sp2.nrrd", spaced + "space: RAST\n"
                                         "space directions: (1,0,0,0) (0,1,0,0) (0,0,1,1)\n\nab")),
        Catch::Contains("time component"));
    // Axes 5.7 degrees from orthogonal: the nearest rotation, with a warning.
    const Volume sheared =
        loadVolume(write("shear.nrrd", spaced + "space: RAS\nspace directions: "
                                                "(1,0,0) (0.1,1,0) (0,0,1)\n\nab"));
    CHECK_THAT(sheared.note, Catch::Contains("sheared orientation: the axes of the space "
                                             "directions are not orthogonal"));
    CHECK(sheared.rotated());
    CHECK_THAT(error(write("sp3.nrrd", spaced + "space: LPS\n"
                                                "space directions: (1,0,0) (0,1,0) (0,0)\n\nab")),
               Catch::Contains("has 2 components, the space has 3"));
}
