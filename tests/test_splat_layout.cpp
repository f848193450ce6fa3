// The compact splat list: positions computed from the index, emission by value.
#include <catch2/catch.hpp>

#include "splat/classify.h"
#include "splat/render.h"
#include "splat/synthetic.h"

using namespace splat;

TEST_CASE("splat list: emission by value equals the per-splat arrays", "[splatter][layout]") {
    const Volume v = makeSynthetic("phantom", 40);
    const TransferFunction tf = TransferFunction::preset("ct-soft").resolved(0.0f, 1.0f);
    ClassifyOptions plain, compact;
    compact.compactEmission = true;
    const SplatList a = classify(v, tf, RenderMode::Dvr, Classification::Pre, 2.0, plain);
    SplatList b = classify(v, tf, RenderMode::Dvr, Classification::Pre, 2.0, compact);
    REQUIRE(a.size() == b.size());
    REQUIRE(a.size() > 1000);
    REQUIRE(!a.paletted());
    REQUIRE(b.paletted());
    CHECK(b.palette.size() <= 65536);
    // 6 bytes of index position and a 2-byte palette index per splat (plus the palette),
    // against 6 + 4 (density) + 16 (emission).
    CHECK(b.density.empty());
    CHECK(b.bytes() == 8 * b.size() + 20 * b.palette.size());
    CHECK(a.bytes() == 26 * a.size());
    for (std::size_t n = 0; n < a.size(); ++n) {
        REQUIRE(b.densityOf(n) == a.density[n]);
        REQUIRE(b.emission(n) == a.emission(n));  // exactly: the same expression per value
        REQUIRE(b.world(n) == v.world(glm::dvec3(a.i[n], a.j[n], a.k[n])));
    }
    b.expandEmission();
    CHECK(!b.paletted());
    CHECK(b.density == a.density);
    CHECK(b.extinction == a.extinction);
    CHECK(b.r == a.r);
}

TEST_CASE("splat list: edge enhancement keeps per-splat emission", "[splatter][layout]") {
    const Volume v = makeSynthetic("phantom", 24);
    const TransferFunction tf = TransferFunction::preset("ct-soft").resolved(0.0f, 1.0f);
    ClassifyOptions o;
    o.compactEmission = true;
    o.edges.gain = 1.0f;
    const SplatList s = classify(v, tf, RenderMode::Dvr, Classification::Pre, 2.0, o);
    REQUIRE(s.size() > 0);
    CHECK(!s.paletted());
    CHECK(s.extinction.size() == s.size());
}
