// The renderers' per-scene state (Scene::Impl::state, model/scene_impl.h): one State per
// type and per level of the pyramid, made once on first use even when frames ask for it
// from several threads at once, and the model's frames unchanged by it.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <vector>

#include "model/scene_impl.h"
#include "splat/render.h"
#include "splat/scene.h"
#include "splat/synthetic.h"

using namespace splat;

namespace {

std::atomic<int> madeA{0}, madeB{0};

/// A renderer's state as the slots see it: counts its constructions, remembers its scene.
struct StateA {
    explicit StateA(const Scene::Impl& s) : scene(&s) { ++madeA; }
    const Scene::Impl* scene;
    int value = 1;
};
struct StateB {
    explicit StateB(const Scene::Impl& s) : scene(&s) { ++madeB; }
    const Scene::Impl* scene;
};

RenderSettings xraySettings() {
    RenderSettings s;
    s.mode = RenderMode::Xray;
    s.camera.width = s.camera.height = 24;
    s.threads = 2;
    return s;
}

}  // namespace

TEST_CASE("scene state: one per type and level, made once, on first use", "[scene][layers]") {
    madeA = 0;
    madeB = 0;
    const Scene scene(makeSynthetic("phantom", 16), xraySettings());
    const Scene::Impl& impl = scene.impl();
    CHECK(madeA == 0);  // nothing made before a renderer asks

    StateA& a = impl.state<StateA>();
    CHECK(madeA == 1);
    CHECK(a.scene == &impl);
    a.value = 7;
    CHECK(&impl.state<StateA>() == &a);  // the same object, its changes kept
    CHECK(impl.state<StateA>().value == 7);
    CHECK(madeA == 1);

    // Another type has its own slot.
    StateB& b = impl.state<StateB>();
    CHECK(madeB == 1);
    CHECK(static_cast<void*>(&b) != static_cast<void*>(&a));

    // A level of the pyramid is a scene of its own: its own state, of that level.
    const Scene::Impl* coarser = impl.coarser();
    REQUIRE(coarser != nullptr);
    StateA& ac = coarser->state<StateA>();
    CHECK(&ac != &a);
    CHECK(ac.scene == coarser);
    CHECK(ac.value == 1);
    CHECK(madeA == 2);
}

TEST_CASE("scene state: frames asking at once from many threads share one state",
          "[scene][layers]") {
    madeA = 0;
    const Scene scene(makeSynthetic("phantom", 16), xraySettings());
    const Scene::Impl& impl = scene.impl();
    std::vector<const StateA*> seen(256, nullptr);
    tbb::parallel_for(0, 256, [&](int n) { seen[std::size_t(n)] = &impl.state<StateA>(); });
    CHECK(madeA == 1);
    for (const StateA* p : seen) CHECK(p == seen.front());
}

TEST_CASE("scene state: a Scene's frames equal the one-call render, renderer caches reused",
          "[scene][layers]") {
    // The splatters and the reference keep tables, orders and fields in the Scene's slots:
    // a second frame of each renderer reads them and draws the same image as a fresh
    // Renderer (which makes them anew).
    const Volume volume = makeSynthetic("phantom", 24);
    RenderSettings s;
    s.camera.width = s.camera.height = 20;
    s.threads = 2;
    const Scene scene(volume, s);
    for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet, RendererKind::Reference}) {
        RenderSettings f = s;
        f.renderer = r;
        f.camera.azimuthDeg = 30;
        const Image first = scene.render(f), second = scene.render(f);
        const Image fresh = render(volume, f);
        REQUIRE(first.pixels.size() == fresh.pixels.size());
        std::size_t differ = 0;
        float largest = 0;
        for (std::size_t p = 0; p < fresh.pixels.size(); ++p) {
            differ += first.pixels[p] != second.pixels[p] || first.pixels[p] != fresh.pixels[p];
            largest = std::max(largest, fresh.pixels[p].a);
        }
        CHECK(differ == 0);
        CHECK(largest > 0.1f);  // the view shows the phantom
    }
}
