// Gaussian scenes (splat/gaussians.h): the 3DGS .ply reader and writer, the generator, and
// one-line errors for malformed files.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "splat/error.h"
#include "splat/gaussians.h"

using namespace splat;

namespace {

std::string tmpFile(const std::string& name) {
    static const std::filesystem::path dir = splat::test::testTmpDir("gaussians");
    return (dir / name).string();
}

// A PLY with the given header lines (between the format line and end_header) and body.
void writePly(const std::string& path, const std::string& format, const std::string& header,
              const std::vector<float>& body) {
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat " << format << " 1.0\n" << header << "end_header\n";
    out.write(reinterpret_cast<const char*>(body.data()), std::streamsize(body.size() * 4));
}

std::string gaussianHeader(std::size_t n, int rest, const std::string& drop = "") {
    std::string h = "element vertex " + std::to_string(n) + "\n";
    std::vector<std::string> names = {"x",  "y",      "z",      "nx",    "ny",
                                      "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
    for (int j = 0; j < rest; ++j) names.push_back("f_rest_" + std::to_string(j));
    for (const char* p :
         {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
        names.push_back(p);
    for (const auto& p : names)
        if (p != drop) h += "property float " + p + "\n";
    return h;
}

std::string errorOf(const std::string& path) {
    try {
        loadGaussians(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST_CASE("3DGS ply: values by name, activations and channel-major f_rest", "[gaussians]") {
    // One Gaussian, SH degree 1: f_rest_j = 100 + j, channel-major (R's 3, then G's, B's).
    std::vector<float> v = {1, 2, 3, 0, 0, 0, 0.1f, 0.2f, 0.3f};
    for (int j = 0; j < 9; ++j) v.push_back(100.0f + float(j));
    const float logit = std::log(0.25f / 0.75f);
    for (float x : {logit, std::log(0.5f), std::log(2.0f), std::log(4.0f), 2.0f, 0.0f, 0.0f, 0.0f})
        v.push_back(x);
    const std::string path = tmpFile("one.ply");
    writePly(path, "binary_little_endian", gaussianHeader(1, 9), v);
    const GaussianScene s = loadGaussians(path);
    REQUIRE(s.size() == 1);
    CHECK(s.shDegree == 1);
    CHECK(s.means[0] == glm::vec3(1, 2, 3));
    CHECK(s.opacities[0] == Approx(0.25).epsilon(1e-6));
    CHECK(s.scales[0].x == Approx(0.5).epsilon(1e-6));
    CHECK(s.scales[0].y == Approx(2.0).epsilon(1e-6));
    CHECK(s.scales[0].z == Approx(4.0).epsilon(1e-6));
    CHECK(s.rotations[0] == glm::vec4(1, 0, 0, 0));  // (2, 0, 0, 0) normalised
    for (int c = 0; c < 3; ++c) {
        CHECK(s.sh[std::size_t(c)] == v[std::size_t(6 + c)]);
        for (int k = 1; k < 4; ++k)
            CHECK(s.sh[std::size_t(k * 3 + c)] == 100.0f + float(c * 3 + k - 1));
    }
}

TEST_CASE("3DGS ply: written and read back, every SH degree", "[gaussians]") {
    GaussianScene s = syntheticGaussians("gaussians:random:300:7");
    REQUIRE(s.size() == 300);
    REQUIRE(s.shDegree == 3);
    s.opacities[0] = 1.0f;  // logit clamps at 40: sigmoid gives 1 back in float
    s.opacities[1] = 0.0f;
    const std::string path = tmpFile("random.ply");
    writeGaussians(s, path);
    const GaussianScene r = loadGaussians(path);
    REQUIRE(r.size() == s.size());
    CHECK(r.shDegree == 3);
    CHECK(r.sh == s.sh);
    CHECK(r.means == s.means);
    double scaleErr = 0, opacityErr = 0, rotErr = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        for (int a = 0; a < 3; ++a)
            scaleErr = std::max(scaleErr, std::abs(double(r.scales[i][a]) / s.scales[i][a] - 1));
        opacityErr = std::max(opacityErr, std::abs(double(r.opacities[i]) - s.opacities[i]));
        rotErr = std::max(rotErr, double(glm::length(r.rotations[i] - s.rotations[i])));
    }
    CHECK(scaleErr < 1e-6);
    CHECK(opacityErr < 1e-6);
    CHECK(rotErr < 1e-6);
    CHECK(r.opacities[0] == 1.0f);
    CHECK(r.opacities[1] < 1e-17f);
    // Degree 0 (no f_rest) survives too.
    GaussianScene pop = syntheticGaussians("gaussians:pop");
    writeGaussians(pop, tmpFile("pop.ply"));
    const GaussianScene p = loadGaussians(tmpFile("pop.ply"));
    CHECK(p.shDegree == 0);
    CHECK(p.sh == pop.sh);
    CHECK(p.opacities[0] == Approx(0.8).epsilon(1e-6));
}

TEST_CASE("3DGS ply: malformed files get one line", "[gaussians]") {
    const std::vector<float> one(17, 0.0f);
    std::vector<float> good = one;
    good[13] = 1.0f;  // rot_0
    auto oneLine = [](const std::string& m) {
        return !m.empty() && m.find('\n') == std::string::npos;
    };

    writePly(tmpFile("ascii.ply"), "ascii", gaussianHeader(1, 0), {});
    std::string m = errorOf(tmpFile("ascii.ply"));
    CHECK(oneLine(m));
    CHECK(m.find("ASCII PLY") != std::string::npos);

    writePly(tmpFile("norot.ply"), "binary_little_endian", gaussianHeader(1, 0, "rot_3"), good);
    m = errorOf(tmpFile("norot.ply"));
    CHECK(oneLine(m));
    CHECK(m.find("missing property 'rot_3'") != std::string::npos);

    // 100 Gaussians declared, one written.
    writePly(tmpFile("short.ply"), "binary_little_endian", gaussianHeader(100, 0), good);
    m = errorOf(tmpFile("short.ply"));
    CHECK(oneLine(m));
    CHECK(m.find("truncated vertex block") != std::string::npos);

    // Absurd counts are refused before anything is allocated.
    writePly(tmpFile("huge.ply"), "binary_little_endian", gaussianHeader(4000000000000ull, 0),
             good);
    m = errorOf(tmpFile("huge.ply"));
    CHECK(oneLine(m));
    CHECK(m.find("exceeds the limit") != std::string::npos);
    writePly(tmpFile("big.ply"), "binary_little_endian", gaussianHeader(200000000, 0), good);
    CHECK(errorOf(tmpFile("big.ply")).find("truncated vertex block") != std::string::npos);

    writePly(tmpFile("mesh.ply"), "binary_little_endian",
             "element face 0\nproperty list uchar int vertex_indices\n", {});
    CHECK(errorOf(tmpFile("mesh.ply")).find("no vertex element") != std::string::npos);

    writePly(tmpFile("rest.ply"), "binary_little_endian", gaussianHeader(1, 5),
             std::vector<float>(22));
    CHECK(errorOf(tmpFile("rest.ply")).find("f_rest") != std::string::npos);

    CHECK(errorOf(tmpFile("absent.ply")).find("cannot open") != std::string::npos);
    // The well-formed one loads.
    writePly(tmpFile("good.ply"), "binary_little_endian", gaussianHeader(1, 0), good);
    CHECK(loadGaussians(tmpFile("good.ply")).size() == 1);
}

TEST_CASE("Gaussian scenes: generator, bounds, geometry and colour", "[gaussians]") {
    const GaussianScene pop = syntheticGaussians("gaussians:pop");
    REQUIRE(pop.size() == 2);
    pop.validate();
    glm::dvec3 lo, hi;
    pop.bounds(lo, hi);
    CHECK(lo.x == Approx(-3.6));
    CHECK(hi.x == Approx(3.6));
    CHECK(hi.z == Approx(3.0));
    const Volume g = pop.geometry();
    CHECK(g.center().x == Approx(0.0).margin(1e-12));
    CHECK(0.5 * glm::length(glm::dvec3(g.dims) * g.spacing) == Approx(0.5 * glm::length(hi - lo)));
    // Degree 0: colour = 0.5 + C0 dc, whatever the direction.
    CHECK(gaussianColour(pop, 0, {0, 1, 0}).x == Approx(1.0f));
    CHECK(gaussianColour(pop, 1, {1, 0, 0}).z == Approx(1.0f));
    // Degree 1: Y_1,-1 = -C1 y, so a unit coefficient on k = 1 adds -C1 dir.y.
    GaussianScene s = pop;
    s.shDegree = 1;
    s.sh.assign(2 * 4 * 3, 0.0f);
    s.sh[3] = 1.0f;  // k = 1, red
    CHECK(gaussianColour(s, 0, {0, 1, 0}).x == Approx(0.5 - 0.4886025119029199));
    CHECK(gaussianColour(s, 0, {0, -1, 0}).x == Approx(0.5 + 0.4886025119029199));
    s.sh[3] = 2.0f;  // 0.5 - 2 C1 < 0: clamped at 0
    CHECK(gaussianColour(s, 0, {0, 1, 0}).x == 0.0f);
    CHECK_THROWS_AS(syntheticGaussians("gaussians:nothing"), Error);
    CHECK_THROWS_AS(syntheticGaussians("gaussians:random:x"), Error);
    GaussianScene bad = pop;
    bad.scales[1].y = 0;
    CHECK_THROWS_AS(bad.validate(), Error);
    CHECK(isGaussianScene("a/b/scene.PLY"));
    CHECK(isGaussianScene("gaussians:pop"));
    CHECK(!isGaussianScene("synthetic:blob"));
}

TEST_CASE("CLI: Gaussian scenes in info, render and splat gaussians", "[gaussians][cli]") {
    using splat::test::runProgram;
    auto r = runProgram(SPLAT_EXE, {"info", "gaussians:pop"});
    CHECK(r.status == 0);
    CHECK(r.out.find("Gaussians: 2, SH degree 0") != std::string::npos);
    CHECK(r.out.find("opacity:   0.8 .. 0.8") != std::string::npos);

    const std::string png = tmpFile("pop.png");
    r = runProgram(SPLAT_EXE, {"render", "gaussians:pop", "--renderer", "sheet", "--slab", "0.1",
                               "--size", "32x32", "-o", png});
    CHECK(r.status == 0);
    CHECK(std::filesystem::file_size(png) > 0);

    r = runProgram(SPLAT_EXE, {"render", "gaussians:pop", "--renderer", "axis", "-o", png});
    CHECK(r.status == 2);
    REQUIRE(r.errLines().size() == 1);
    CHECK(r.errLines()[0].find("splat: error: unknown Gaussian renderer") == 0);

    writePly(tmpFile("cli_ascii.ply"), "ascii", gaussianHeader(1, 0), {});
    r = runProgram(SPLAT_EXE, {"info", tmpFile("cli_ascii.ply")});
    CHECK(r.status == 1);
    REQUIRE(r.errLines().size() == 1);
    CHECK(r.errLines()[0].find("ASCII PLY") != std::string::npos);

    const std::string ply = tmpFile("blob.ply");
    r = runProgram(SPLAT_EXE, {"gaussians", "synthetic:blob:8", "-o", ply});
    CHECK(r.status == 0);
    const GaussianScene s = loadGaussians(ply);
    CHECK(s.size() > 10);
    CHECK(s.scales[0].x == Approx(0.65f));
}

TEST_CASE("CLI: splat popping of a Gaussian scene", "[gaussians][cli][popping]") {
    using splat::test::runProgram;
    const std::string dir = splat::test::testTmpDir("gaussians_popping").string();
    auto r = runProgram(SPLAT_EXE, {"popping", "gaussians:pop", "--from", "-5.5", "--to", "5.5",
                                    "--step", "1", "--size", "32x32", "--slab", "0.05",
                                    "--ref-tolerance", "1e-5", "--refine", "4", "--no-flip", "-q",
                                    "--report", dir});
    CHECK(r.status == 0);
    CHECK(r.out.find("predicted order swap at 0.000000 degrees") != std::string::npos);
    CHECK(r.out.find("event (3dgs) -0.5..0.5") != std::string::npos);
    CHECK(r.out.find("event (3dgs-pixel) -0.5..0.5") != std::string::npos);
    CHECK(r.out.find("event (sheet)") == std::string::npos);
    CHECK(r.out.find("event (reference)") == std::string::npos);
    const std::string summary = splat::test::readTextFile(dir + "/summary.json");
    CHECK(summary.find("\"3dgs-pixel\"") != std::string::npos);
    CHECK(std::filesystem::exists(dir + "/report.html"));
    CHECK(!std::filesystem::exists(dir + "/.frames"));

    r = runProgram(SPLAT_EXE, {"popping", "gaussians:pop", "--from", "-2.5", "--to", "2.5",
                               "--step", "1", "--renderers", "3dgs,axis", "--report", dir});
    CHECK(r.status == 2);
    REQUIRE(r.errLines().size() == 1);
    CHECK(r.errLines()[0].find("splat: error: unknown Gaussian renderer") == 0);
}
