// Progress and cancel inside one frame: every renderer reports a total
// known up front, counts up to it in order, and stops within a tile, chunk or row of a cancel.
#include <catch2/catch.hpp>
#include <atomic>
#include <chrono>

#include "splat/render.h"
#include "splat/synthetic.h"

using namespace splat;

namespace {
RenderSettings frame(RendererKind r) {
    RenderSettings s;
    s.renderer = r;
    s.transfer = TransferFunction::preset("ct-soft");
    s.camera.width = s.camera.height = 160;
    s.camera.azimuthDeg = 30;
    s.threads = 2;
    s.quality.tileSize = 16;
    return s;
}
}  // namespace

TEST_CASE("frame: progress counts to a total known up front, and cancel stops the frame",
          "[cancel]") {
    const Volume v = makeSynthetic("phantom", 48);
    for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet, RendererKind::Reference}) {
        INFO(toString(r));
        RenderSettings s = frame(r);
        const Scene scene(v, s);
        std::size_t calls = 0, last = 0, total = 0;
        bool ordered = true, fixedTotal = true;
        s.progress = [&](std::size_t done, std::size_t t, const std::string&) {
            if (calls++ == 0) total = t;
            ordered = ordered && done == last + 1;
            fixedTotal = fixedTotal && t == total;
            last = done;
            return true;
        };
        const Image full = scene.render(s);
        CHECK(ordered);
        CHECK(fixedTotal);
        CHECK(total > 1);
        CHECK(last == total);  // every unit reported once, ending at the total
        RenderSettings quiet = s;
        quiet.progress = nullptr;
        CHECK(scene.render(quiet).pixels == full.pixels);  // observing changes no pixel

        // Cancel at the first report: the frame throws Cancelled and does far less work.
        std::size_t after = 0;
        s.progress = [&](std::size_t, std::size_t, const std::string&) {
            ++after;
            return false;
        };
        CHECK_THROWS_AS(scene.render(s), Cancelled);
        CHECK(after == 1);  // nothing reported after the cancel
    }
}

TEST_CASE("frame: a long reference frame stops soon after cancel", "[cancel]") {
    const Volume v = makeSynthetic("phantom", 64);
    RenderSettings s = frame(RendererKind::Reference);
    s.camera.width = s.camera.height = 384;
    const Scene scene(v, s);
    std::atomic<bool> stop{false};
    std::size_t rows = 0, total = 0;
    s.progress = [&](std::size_t done, std::size_t t, const std::string&) {
        rows = done;
        total = t;
        return !(done >= 8 || stop.load());
    };
    CHECK_THROWS_AS(scene.render(s), Cancelled);
    CHECK(total == 384);
    CHECK(rows == 8);  // no row reported after the one that cancelled
}
