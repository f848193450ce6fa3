// The library boundary: lifetimes the compiler enforces, settings and in-memory
// volumes validated where they enter, and one rule for what a frame may change.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <limits>
#include <type_traits>

#include "splat/error.h"
#include "splat/render.h"
#include "splat/synthetic.h"

using namespace splat;

namespace {

RenderSettings small() {
    RenderSettings s;
    s.camera.width = s.camera.height = 24;
    s.threads = 2;
    s.transfer = TransferFunction::preset("gray-ramp");
    return s;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

}  // namespace

// Finding 3: `const Scene scene(makeSynthetic("blob", 32), s)` bound the temporary and
// dangled (stack-use-after-scope under ASan). A temporary is now moved in and owned; a const
// temporary, which can be neither moved nor kept, does not compile.
static_assert(std::is_constructible_v<Scene, Volume&&, const RenderSettings&>);
static_assert(!std::is_constructible_v<Scene, const Volume&&, const RenderSettings&>);
static_assert(!std::is_constructible_v<Renderer, const Volume&&, const RenderSettings&>);

TEST_CASE("library: a Scene or Renderer made from a temporary volume owns it", "[library]") {
    const RenderSettings s = small();
    const Scene owned(makeSynthetic("blob", 16), s);  // the temporary dies here
    const Volume kept = makeSynthetic("blob", 16);
    const Scene borrowed(kept, s);
    CHECK(owned.render(s).pixels == borrowed.render(s).pixels);
    const Renderer r(makeSynthetic("blob", 16), s);
    CHECK(r.render().pixels == borrowed.render(s).pixels);
    CHECK(owned.volume().voxelCount() == 16u * 16u * 16u);
}

TEST_CASE("library: settings and volumes are validated where they enter", "[library]") {
    const Volume v = makeSynthetic("blob", 12);
    RenderSettings s = small();
    s.transfer.unitDistance = 0;  // rendered NaN pixels before
    CHECK_THAT(errorOf([&] { Scene(v, s); }), Catch::Contains("unit_distance"));
    s = small();
    s.transfer.points.clear();
    CHECK_THAT(errorOf([&] { Scene(v, s); }), Catch::Contains("no points"));
    s = small();
    std::swap(s.transfer.points[0], s.transfer.points[2]);
    CHECK_THAT(errorOf([&] { Scene(v, s); }), Catch::Contains("non-decreasing"));
    s = small();
    s.transfer.points[1].value = std::numeric_limits<float>::quiet_NaN();
    CHECK_THAT(errorOf([&] { Scene(v, s); }), Catch::Contains("non-finite"));

    // NaN/Inf samples: 0.1% NaN changed the image-aligned mip peak only; all-NaN gave a blank
    // image. Both are refused with the loaders' policy.
    Volume nan = v;
    nan.data[nan.voxelCount() / 2] = std::numeric_limits<float>::quiet_NaN();
    nan.data[3] = std::numeric_limits<float>::infinity();
    CHECK_THAT(errorOf([&] { Scene(nan, small()); }), Catch::Contains("2 NaN/Inf samples"));
    Volume bg = v;
    bg.background = std::numeric_limits<float>::quiet_NaN();
    CHECK_THAT(errorOf([&] { Scene(bg, small()); }), Catch::Contains("background"));
}

TEST_CASE("library: a frame may not change what the Scene classified with", "[library]") {
    const Volume v = makeSynthetic("sphere", 16);
    const RenderSettings s = small();
    const Scene scene(v, s);
    // Camera, renderer, order, threads and the per-frame quality knobs may change.
    RenderSettings frame = s;
    frame.camera.azimuthDeg = 40;
    frame.renderer = RendererKind::Sheet;
    frame.quality.slab = 0.5;
    CHECK(scene.render(frame).pixels == Renderer(v, frame).render().pixels);
    CHECK_NOTHROW(scene.render(scene.settings()));  // the resolved settings are the same scene

    // A moved control point or clip plane returned the old image before; now refused by name.
    frame = s;
    frame.transfer.points.back().rgba.a = 0.5f;
    CHECK_THAT(errorOf([&] { scene.render(frame); }), Catch::Contains("RenderSettings::transfer"));
    frame = s;
    frame.clipping.planes.push_back({glm::dvec3(8.0), glm::dvec3(1, 0, 0)});
    CHECK_THAT(errorOf([&] { scene.render(frame); }), Catch::Contains("RenderSettings::clipping"));
    frame = s;
    frame.mode = RenderMode::Mip;
    CHECK_THAT(errorOf([&] { scene.render(frame); }), Catch::Contains("RenderSettings::mode"));
    frame = s;
    frame.shading.light = glm::vec3(1, 0, 0);
    CHECK_THAT(errorOf([&] { scene.render(frame); }), Catch::Contains("RenderSettings::shading"));
    frame = s;
    frame.edges.gain = 1.0f;
    CHECK_THAT(errorOf([&] { scene.render(frame); }), Catch::Contains("RenderSettings::edges"));
    frame = s;
    frame.kernel = "bspline";
    CHECK_THAT(errorOf([&] { scene.render(frame); }), Catch::Contains("RenderSettings::kernel"));
}
