// Clipping cuts the reconstructed field, not the voxels: the cut face shows the cut
// data where the plane is, in every renderer; a kept region holding everything changes no pixel.
#include <catch2/catch.hpp>
#include <cmath>

#include "reference_util.h"
#include "techniques_util.h"

using namespace splat;
using namespace splat::test;

namespace {

struct Deviation {
    double worst = 0, mean = 0;
    int pixels = 0;
};

// X-ray images a and b over the pixels whose ray passes within `half` of the volume centre
// (world units, both image directions): the line integral of a constant 1 is the kept length,
// so a - b is the disagreement about where the cut lies along the ray, in world units.
Deviation xrayDeviation(const Image& a, const Image& b, const Camera& cam, double half) {
    Deviation d;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            const Ray r = cam.ray(x + 0.5, y + 0.5);
            const glm::dvec3 off = r.origin - cam.target;
            if (std::abs(glm::dot(off, cam.right)) > half || std::abs(glm::dot(off, cam.up)) > half)
                continue;
            const double e = std::abs(double(a.at(x, y).r) - double(b.at(x, y).r));
            d.worst = std::max(d.worst, e);
            d.mean += e;
            ++d.pixels;
        }
    if (d.pixels) d.mean /= d.pixels;
    return d;
}

}  // namespace

TEST_CASE("clipping: the cut lies where the plane is, splatters against the reference",
          "[techniques]") {
    // A constant volume cut by oblique planes and seen in X-ray: each pixel's value is the
    // kept length of its ray, so comparing it with the reference (which clips its ray exactly)
    // measures where each renderer puts the cut, in voxels.
    const int n = 24;
    const Volume v = onesVolume(n);
    struct Case {
        glm::dvec3 normal;
        double azimuth, elevation, slab;
    };
    const Case cases[] = {{{1, -1, 0}, 0, 0, 1.0},
                          {{0.3, -1, 0.2}, 20, 10, 1.0},
                          {{0.3, -1, 0.2}, 20, 10, 0.5},
                          {{-0.5, -1, -0.4}, 35, -20, 1.0}};
    for (const Case& c : cases) {
        RenderSettings s = techniqueSettings(RendererKind::Reference, RenderMode::Xray, 48);
        s.camera.pixelSize = 0.5;
        s.camera.azimuthDeg = c.azimuth;
        s.camera.elevationDeg = c.elevation;
        s.quality.slab = c.slab;
        s.clipping.planes.push_back(
            {v.center() + glm::dvec3(0.3, 0.0, 0.0), glm::normalize(c.normal)});
        const Image ref = render(v, s);
        const Camera cam(s.camera, v);
        // The voxel cut this replaces: voxels beyond the plane dropped (set to 0) and the rest
        // reconstructed, whose kept length follows the voxel staircase.
        Volume dropped = v;
        for (int k = 0; k < n; ++k)
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i)
                    if (!s.clipping.keeps(v.world(glm::dvec3(i, j, k)))) dropped.at(i, j, k) = 0;
        RenderSettings whole = s;
        whole.clipping.planes.clear();
        const Deviation voxelCut = xrayDeviation(render(dropped, whole), ref, cam, 5.0);
        for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet}) {
            s.renderer = r;
            const Deviation d = xrayDeviation(render(v, s), ref, cam, 5.0);
            INFO(toString(r) << " normal " << c.normal.x << "," << c.normal.y << "," << c.normal.z
                             << " azimuth " << c.azimuth << " slab " << c.slab
                             << ": kept length vs reference worst " << d.worst << " mean " << d.mean
                             << " voxels over " << d.pixels << " pixels; the voxel cut: worst "
                             << voxelCut.worst << " mean " << voxelCut.mean);
            CHECK(d.pixels > 300);
            CHECK(d.worst < 0.02);
            CHECK(d.mean < 0.005);
            CHECK(voxelCut.worst > 0.1);  // what the exact cut removes
        }
    }
}

TEST_CASE("clipping: the cut face of a constant volume has the constant's colour, pre and post",
          "[techniques]") {
    // A constant volume cut obliquely, seen obliquely: every pixel whose ray meets the cut
    // face shows the transfer function's colour of the constant (colour / alpha), in every
    // renderer and both classifications.
    const Volume v = onesVolume(24);
    const TransferFunction tf = greenTf();
    for (Classification c : {Classification::Pre, Classification::Post})
        for (RendererKind r : kAllRenderers) {
            RenderSettings s = techniqueSettings(r, RenderMode::Dvr, 48);
            s.classification = c;
            s.transfer = tf;
            s.camera.azimuthDeg = 25;
            s.camera.elevationDeg = 15;
            s.camera.pixelSize = 0.5;
            s.clipping.planes.push_back({v.center(), glm::normalize(glm::dvec3(0.2, -1, 0.3))});
            const Image img = render(v, s);
            const Camera cam(s.camera, v);
            double worst = 0;
            int n = 0;
            for (int y = 0; y < 48; ++y)
                for (int x = 0; x < 48; ++x) {
                    const Ray ray = cam.ray(x + 0.5, y + 0.5);
                    const glm::dvec3 off = ray.origin - cam.target;
                    if (std::abs(glm::dot(off, cam.right)) > 6 ||
                        std::abs(glm::dot(off, cam.up)) > 6)
                        continue;
                    const glm::vec4 p = img.at(x, y);
                    if (p.a < 0.999f) continue;
                    worst = std::max({worst, std::abs(p.r - 0.2 * p.a), std::abs(p.g - 0.9 * p.a),
                                      std::abs(p.b - 0.3 * p.a)});
                    ++n;
                }
            INFO(toString(r) << " " << toString(c) << ": " << n << " opaque cut-face pixels, worst "
                             << worst);
            CHECK(n > 300);
            CHECK(worst < 1e-3);
        }
}

TEST_CASE("clipping: a kept region holding everything changes no pixel, in every mode",
          "[techniques]") {
    const Volume v = makeSynthetic("blob", 20);
    const RenderMode modes[] = {RenderMode::Dvr, RenderMode::Mip, RenderMode::Xray,
                                RenderMode::Iso};
    for (RenderMode m : modes)
        for (Classification c : {Classification::Pre, Classification::Post})
            for (RendererKind r : kAllRenderers) {
                if (m != RenderMode::Dvr && c == Classification::Post) continue;
                INFO(toString(m) << " " << toString(r) << " " << toString(c));
                RenderSettings s = techniqueSettings(r, m, 32);
                s.classification = c;
                s.shading.enabled = m != RenderMode::Xray && m != RenderMode::Mip;
                s.isoLevel = 0.4;
                const Image plain = render(v, s);
                s.clipping.cropBox = true;
                s.clipping.boxMin = glm::dvec3(-3.0);
                s.clipping.boxMax = glm::dvec3(23.0);
                s.clipping.planes.push_back({glm::dvec3(30.0), glm::dvec3(1, 1, 1)});
                CHECK(render(v, s).pixels == plain.pixels);
                // A region that cuts only kernel tails beyond the samples changes pixels a
                // little, but it does change them: the field, not the voxels, is cut.
                s.clipping.boxMin = glm::dvec3(-0.5);
                s.clipping.boxMax = glm::dvec3(19.5);
                const Image tails = render(v, s);
                CHECK(compareImages(tails, plain).maxAbs < 0.05);
            }
}

TEST_CASE("clipping: iso surfaces are capped at the cut in every renderer", "[techniques]") {
    // The sphere cut through its centre, seen face on: the cut face is a disc of the sphere's
    // radius at the plane's depth, in the splatters as in the reference.
    const Volume v = makeSynthetic("sphere", 32);
    const double R = syntheticSphereRadius(32);
    Image depth[3];
    int idx = 0;
    for (RendererKind r : kAllRenderers) {
        RenderSettings s = techniqueSettings(r, RenderMode::Iso, 48);
        s.camera.pixelSize = 0.75;
        s.isoLevel = 0.5;
        s.clipping.planes.push_back({v.center(), glm::dvec3(0, -1, 0)});  // keeps y >= centre
        Scene scene(v, s);
        const Image img = scene.render(s);
        depth[idx] = scene.renderIsoDepth(s);
        const Camera cam(s.camera, v);
        int inside = 0, hits = 0;
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 48; ++x) {
                if (impactOf(cam, x, y) > R - 1.5) continue;
                ++inside;
                if (img.at(x, y).a == 1.0f) ++hits;
            }
        INFO(toString(r) << ": " << hits << " of " << inside << " pixels inside the disc hit");
        CHECK(hits == inside);
        ++idx;
    }
    // Hit depths on the cut face against the reference's (the plane's depth).
    for (int r = 0; r < 2; ++r) {
        double worst = 0;
        for (int y = 16; y < 32; ++y)
            for (int x = 16; x < 32; ++x)
                if (depth[2].at(x, y).a > 0 && depth[r].at(x, y).a > 0)
                    worst = std::max(worst,
                                     std::abs(double(depth[r].at(x, y).r - depth[2].at(x, y).r)));
        INFO(toString(kAllRenderers[r]) << ": cut-face depth vs reference, worst " << worst);
        CHECK(worst < 0.05);
    }
}

TEST_CASE("clipping: a varying field cut obliquely, splatters against the reference",
          "[techniques]") {
    // Where the field varies across a sheet, cutting the sheet's path by its kept fraction
    // assumes the field constant along the cut part: the error this adds is what the cut costs
    // over the uncut splatter (the image-aligned slab is cut inside; the axis-aligned sheet
    // holds whole kernels of its slice).
    const Volume v = makeSynthetic("blob", 32);
    for (RenderMode m : {RenderMode::Xray, RenderMode::Dvr, RenderMode::Mip})
        for (Projection proj : {Projection::Orthographic, Projection::Perspective}) {
            RenderSettings s = techniqueSettings(RendererKind::Reference, m, 48);
            s.camera.projection = proj;
            s.camera.fovDeg = 30;
            s.transfer = TransferFunction::preset("gray-ramp").resolved(0, 1);
            s.camera.azimuthDeg = 20;
            s.camera.elevationDeg = 10;
            s.quality.earlyTermination = 0;
            const Image refWhole = render(v, s);
            s.clipping.planes.push_back(
                {v.center() + glm::dvec3(0.4, 0.0, 0.2), glm::normalize(glm::dvec3(0.3, -1, 0.2))});
            const Image refCut = render(v, s);
            double scale = 0;
            for (const auto& p : refWhole.pixels) scale = std::max(scale, double(p.r));
            for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet}) {
                s.renderer = r;
                RenderSettings whole = s;
                whole.clipping.planes.clear();
                const double uncut = compareImages(render(v, whole), refWhole).maxAbs / scale;
                const double cut = compareImages(render(v, s), refCut).maxAbs / scale;
                INFO(toString(m) << " " << toString(proj) << " " << toString(r)
                                 << ": worst error relative to the peak, cut " << cut << ", uncut "
                                 << uncut);
                // MIP takes the mean of the cut part of a sheet as the mean of the whole: the
                // splatters' MIP (a maximum of sheet means) is approximate already uncut.
                const double added = cut - uncut;
                CHECK(added < (m == RenderMode::Mip       ? 0.01
                               : r == RendererKind::Sheet ? 0.002
                                                          : 0.015));
            }
        }
}
