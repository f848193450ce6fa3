// Segmentation labels: nearest-label classification, never interpolated.
#include <catch2/catch.hpp>
#include <cmath>

#include "reference_util.h"
#include "techniques_util.h"

using namespace splat;
using namespace splat::test;

namespace {

// Three boxes side by side along x (labels 1, 2, 3), background 0.
Volume threeBoxes() {
    Volume v = makeVolume(glm::ivec3(24), glm::dvec3(1.0), "labels");
    for (int k = 6; k < 18; ++k)
        for (int j = 6; j < 18; ++j)
            for (int i = 3; i < 21; ++i) v.at(i, j, k) = float(1 + (i - 3) / 6);
    return v;
}

Labels table() {
    Labels l;
    l.enabled = true;
    l.table = {glm::vec4(0.0f),
               {1.0f, 0.0f, 0.0f, 1.0f},
               {0.0f, 1.0f, 0.0f, 1.0f},
               {0.0f, 0.0f, 1.0f, 1.0f}};
    return l;
}

// The table colour a premultiplied pixel shows, or -1 when it is none of them.
int colourIndex(const glm::vec4& p, const Labels& l) {
    const glm::vec3 c = glm::vec3(p) / p.a;
    for (std::size_t n = 1; n < l.table.size(); ++n)
        if (glm::length(c - glm::vec3(l.table[n])) < 1e-3f) return int(n);
    return -1;
}

}  // namespace

TEST_CASE(
    "labels: only table colours appear, each region shows its own, selection shows only "
    "the selected",
    "[techniques]") {
    const Volume v = threeBoxes();
    for (RendererKind r : kAllRenderers) {
        RenderSettings s = techniqueSettings(r, RenderMode::Dvr, 64);
        s.labels = table();
        s.camera.azimuthDeg = 25;
        s.camera.elevationDeg = 20;
        const Image im = render(v, s);
        int counts[4] = {0, 0, 0, 0}, foreign = 0, shown = 0;
        for (const auto& p : im.pixels) {
            if (p.a < 1e-3f) continue;
            ++shown;
            const int c = colourIndex(p, s.labels);
            if (c < 0)
                ++foreign;
            else
                ++counts[c];
        }
        INFO(toString(r) << ": " << shown << " pixels, " << foreign << " not a table colour; "
                         << counts[1] << "/" << counts[2] << "/" << counts[3]);
        CHECK(shown > 500);
        // Splatters: never (the sheet pixel takes one label). The reference integrates a
        // discontinuous label field with Simpson's rule, which blends neighbouring labels
        // along a ray at their borders: a few border pixels.
        CHECK(foreign <= (r == RendererKind::Reference ? shown / 20 : 0));
        for (int c = 1; c <= 3; ++c) CHECK(counts[c] > shown / 10);
        // The box centres show their own colours (left box red, middle green, right blue).
        const Camera cam(s.camera, v);
        for (int c = 1; c <= 3; ++c) {
            const glm::dvec3 centre(3 + 6 * (c - 1) + 2.5, 6, 11.5);  // on the front face
            const glm::dvec3 px = cam.project(centre);
            CHECK(colourIndex(im.at(int(px.x), int(px.y)), s.labels) == c);
        }
        s.labels.selection = {2};
        const Image only = render(v, s);
        int others = 0, green = 0;
        for (const auto& p : only.pixels) {
            if (p.a < 1e-3f) continue;
            const int c = colourIndex(p, s.labels);
            green += c == 2;
            others += c != 2;
        }
        CHECK(green > 100);
        CHECK(others <= (r == RendererKind::Reference ? green / 20 : 0));
    }
}
