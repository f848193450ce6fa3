// Surface export: the mesh of f = level lies on the level set of the reconstructed
// field, is closed and outward-oriented for a closed object, has a sphere's volume and area,
// needs no box faces on CT data in HU, and survives a round trip through each file format.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "cli_util.h"
#include "splat/surface.h"
#include "splat/synthetic.h"
#include "splat/views.h"

using namespace splat;
using namespace splat::test;

namespace {
constexpr double kPi = 3.14159265358979323846;

// A ball of radius r (voxels, world = index) with a smooth edge, value inside `in`, outside
// `out`, background `out`.
Volume ball(int n, double r, float in, float out) {
    Volume v = makeVolume(glm::ivec3(n), glm::dvec3(1.0), "ball");
    const double c = (n - 1) / 2.0;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double d = glm::length(glm::dvec3(i, j, k) - c);
                const double t = std::clamp((r + 1.5 - d) / 3.0, 0.0, 1.0);
                v.at(i, j, k) = float(out + (in - out) * t);
            }
    v.background = out;
    return v;
}

struct Topology {
    bool closed = true, oriented = true;
    long euler = 0;
};

Topology topology(const Mesh& m) {
    std::map<std::pair<unsigned, unsigned>, int> directed;
    for (const auto& t : m.triangles)
        for (int e = 0; e < 3; ++e) directed[{t[e], t[(e + 1) % 3]}]++;
    Topology r;
    std::size_t undirected = 0;
    for (const auto& [e, count] : directed) {
        if (count != 1) r.oriented = false;
        const auto back = directed.find({e.second, e.first});
        if (back == directed.end() || back->second != 1) r.closed = false;
        if (e.first < e.second) ++undirected;
    }
    r.euler = long(m.vertices.size()) - long(undirected) + long(m.triangles.size());
    return r;
}

double enclosedVolume(const Mesh& m) {  // divergence theorem
    double v = 0;
    for (const auto& t : m.triangles)
        v += glm::dot(glm::dvec3(m.vertices[t.x]),
                      glm::cross(glm::dvec3(m.vertices[t.y]), glm::dvec3(m.vertices[t.z])));
    return v / 6.0;
}

double area(const Mesh& m) {
    double a = 0;
    for (const auto& t : m.triangles)
        a += 0.5 * glm::length(glm::cross(glm::dvec3(m.vertices[t.y] - m.vertices[t.x]),
                                          glm::dvec3(m.vertices[t.z] - m.vertices[t.x])));
    return a;
}
}  // namespace

TEST_CASE("surface: a ball's iso surface is on the level set, closed and a sphere",
          "[surface]") {
    const Volume v = ball(28, 8.0, 1.0f, 0.0f);
    const Mesh m = extractIsosurface(v, 0.5);
    REQUIRE(m.triangles.size() > 500);
    const FieldView f(v);
    double worst = 0;
    for (const auto& p : m.vertices) worst = std::max(worst, std::abs(f(glm::dvec3(p)) - 0.5));
    CHECK(worst < 1e-4);
    CHECK(m.maxResidual < 1e-4);
    const Topology t = topology(m);
    CHECK(t.closed);
    CHECK(t.oriented);
    CHECK(t.euler == 2);
    // A sphere: volume and area agree with one radius (the mean vertex distance).
    const glm::dvec3 c = v.center();
    double rs = 0;
    for (const auto& p : m.vertices) rs += glm::length(glm::dvec3(p) - c);
    rs /= double(m.vertices.size());
    CHECK_THAT(enclosedVolume(m), Catch::Matchers::WithinRel(4.0 / 3.0 * kPi * rs * rs * rs, 0.02));
    CHECK_THAT(area(m), Catch::Matchers::WithinRel(4.0 * kPi * rs * rs, 0.03));
    // Outward: each normal points away from the centre.
    for (std::size_t n = 0; n < m.vertices.size(); ++n)
        REQUIRE(glm::dot(glm::dvec3(m.normals[n]), glm::dvec3(m.vertices[n]) - c) > 0);
}

TEST_CASE("surface: CT in HU at -500 is one closed surface with nothing on the box",
          "[surface]") {
    const Volume v = ball(24, 7.0, 40.0f, -1000.0f);  // tissue in air, b = -1000
    const Mesh m = extractIsosurface(v, -500.0);
    const Topology t = topology(m);
    CHECK(t.closed);
    CHECK(t.euler == 2);
    for (const auto& p : m.vertices)
        for (int k = 0; k < 3; ++k) {
            REQUIRE(p[k] > 2.0f);  // far from the faces at 0 and 23
            REQUIRE(p[k] < 21.0f);
        }
    Volume zero = v;  // with b = 0 the field crosses -500 again at the box faces
    zero.background = 0.0f;
    CHECK(topology(extractIsosurface(zero, -500.0)).euler == 4);
}

TEST_CASE("surface: PLY, OBJ and STL round trips, and the CLI", "[surface]") {
    const Volume v = ball(16, 4.0, 1.0f, 0.0f);
    const Mesh m = extractIsosurface(v, 0.5);
    const std::string dir = SPLAT_TEST_TMP;
    std::filesystem::create_directories(dir);
    writeMesh(dir + "/s.ply", m);
    writeMesh(dir + "/s.stl", m);
    writeMesh(dir + "/s.obj", m);
    auto slurp = [](const std::string& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    };
    {  // PLY: header counts, then the first vertex and the last face as written
        const std::string s = slurp(dir + "/s.ply");
        const std::size_t end = s.find("end_header\n") + 11;
        CHECK(s.find("element vertex " + std::to_string(m.vertices.size())) != std::string::npos);
        CHECK(s.find("element face " + std::to_string(m.triangles.size())) != std::string::npos);
        REQUIRE(s.size() == end + m.vertices.size() * 24 + m.triangles.size() * 13);
        float x;
        std::memcpy(&x, s.data() + end, 4);
        CHECK(x == m.vertices[0].x);
        std::int32_t last;
        std::memcpy(&last, s.data() + s.size() - 4, 4);
        CHECK(std::uint32_t(last) == m.triangles.back().z);
    }
    {  // STL: 84 + 50 bytes per triangle; the first vertex of the first facet
        const std::string s = slurp(dir + "/s.stl");
        REQUIRE(s.size() == 84 + 50 * m.triangles.size());
        float y;
        std::memcpy(&y, s.data() + 84 + 12 + 4, 4);
        CHECK(y == m.vertices[m.triangles[0].x].y);
    }
    {  // OBJ: counts of v, vn, f lines and the first face's indices
        std::istringstream in(slurp(dir + "/s.obj"));
        std::size_t nv = 0, nn = 0, nf = 0;
        std::string first;
        for (std::string line; std::getline(in, line);) {
            if (line.rfind("v ", 0) == 0) ++nv;
            if (line.rfind("vn ", 0) == 0) ++nn;
            if (line.rfind("f ", 0) == 0 && nf++ == 0) first = line;
        }
        CHECK(nv == m.vertices.size());
        CHECK(nn == m.vertices.size());
        CHECK(nf == m.triangles.size());
        const auto& t = m.triangles[0];
        CHECK(first == "f " + std::to_string(t.x + 1) + "//" + std::to_string(t.x + 1) + " " +
                           std::to_string(t.y + 1) + "//" + std::to_string(t.y + 1) + " " +
                           std::to_string(t.z + 1) + "//" + std::to_string(t.z + 1));
    }
    CHECK_THROWS_WITH(writeMesh(dir + "/s.xyz", m), Catch::Contains("unknown mesh format"));

    const RunResult ok = runSplat({"iso", "synthetic:sphere:24", "--level", "0.5", "-o", dir + "/c.ply"});
    CHECK(ok.status == 0);
    CHECK(ok.out.find("triangles") != std::string::npos);
    const RunResult nan = runSplat({"iso", "synthetic:sphere:24", "--level", "nan", "-o", dir + "/n.ply"});
    CHECK(nan.status == 2);
    const RunResult out = runSplat({"iso", "synthetic:sphere:24", "--level", "7", "-o", dir + "/o.ply"});
    CHECK(out.status == 1);
    CHECK(out.err.find("no surface at level 7") != std::string::npos);
    CHECK(!std::filesystem::exists(dir + "/o.ply"));
    const RunResult ext = runSplat({"iso", "synthetic:sphere:24", "--level", "0.5", "-o", dir + "/c.xyz"});
    CHECK(ext.status == 2);
}
