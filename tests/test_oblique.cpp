// Oblique volumes in their true orientation: Volume::direction rotates the
// volume's frame into the world, and the Camera turns its world parameters into the volume's
// frame (docs/design.md "World frame"), so an oblique volume is a change of basis of the
// view, never a resampling.
#include <catch2/catch.hpp>
#include <cmath>

#include "cli_util.h"
#include "splat/camera.h"
#include "splat/render.h"
#include "splat/synthetic.h"
#include "splat/volume_io.h"

using namespace splat;
using namespace splat::test;

namespace {
constexpr double kPi = 3.14159265358979323846;

// Rotation by `deg` about `axis` (Rodrigues).
glm::dmat3 rotation(glm::dvec3 axis, double deg) {
    axis = glm::normalize(axis);
    const double t = deg * kPi / 180, c = std::cos(t), s = std::sin(t);
    glm::dmat3 R;
    for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row)
            R[col][row] = (row == col ? c : 0.0) + (1 - c) * axis[row] * axis[col] +
                          (row == col ? 0.0
                                      : s * ((row + 1) % 3 == col ? -axis[3 - row - col]
                                                                  : axis[3 - row - col]));
    return R;
}

double maxAbsDiff(const Image& a, const Image& b) {
    double w = 0;
    for (std::size_t n = 0; n < a.pixels.size(); ++n)
        for (int c = 0; c < 4; ++c)
            w = std::max(w, double(std::abs(a.pixels[n][c] - b.pixels[n][c])));
    return w;
}

double maxValue(const Image& a) {
    double w = 0;
    for (const glm::vec4& p : a.pixels) w = std::max(w, double(p.r));
    return w;
}

const RendererKind kRenderers[] = {RendererKind::Axis, RendererKind::Sheet,
                                   RendererKind::Reference};

// A ball of radius r (voxel units, unit spacing) at index c, value 1, in a 40 x 36 x 30 grid.
Volume ball(const glm::dvec3& c, double r) {
    Volume v = makeVolume({40, 36, 30}, glm::dvec3(1.0), "ball");
    for (int k = 0; k < v.dims.z; ++k)
        for (int j = 0; j < v.dims.y; ++j)
            for (int i = 0; i < v.dims.x; ++i)
                v.at(i, j, k) = glm::length(glm::dvec3(i, j, k) - c) <= r ? 1.0f : 0.0f;
    return v;
}

// X-ray of the ball against the chord length 2 sqrt(r^2 - b^2) of each pixel's world ray
// (b: its distance from the ball's world centre), over pixels with b < 0.7 r: the rms relative
// error. The rays are made here from the orbit formula in world coordinates, not by Camera.
double chordError(const Image& im, const Volume& v, const CameraParams& p, const glm::dvec3& c,
                  double r) {
    const double a = p.azimuthDeg * kPi / 180, e = p.elevationDeg * kPi / 180;
    const glm::dvec3 view(-std::sin(a) * std::cos(e), std::cos(a) * std::cos(e), -std::sin(e));
    const glm::dvec3 right(std::cos(a), std::sin(a), 0.0), up = glm::cross(right, view);
    const glm::dvec3 target = v.direction * v.center(), centre = v.worldPosition(c);
    double sumSq = 0;
    int count = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            const glm::dvec3 o = target + right * ((x + 0.5 - 0.5 * im.width) * p.pixelSize) -
                                 up * ((y + 0.5 - 0.5 * im.height) * p.pixelSize);
            const glm::dvec3 d = o - centre;
            const double b = glm::length(d - view * glm::dot(d, view));
            if (b > 0.7 * r) continue;
            const double rel = im.at(x, y).r / (2.0 * std::sqrt(r * r - b * b)) - 1.0;
            sumSq += rel * rel;
            ++count;
        }
    CHECK(count > 80);  // pi (0.7 r)^2 = 98 pixels of size 1
    return count ? std::sqrt(sumSq / count) : 1.0;
}
}  // namespace

TEST_CASE("oblique: a volume rendered from a camera rotated with it is the unrotated image",
          "[oblique][camera]") {
    const Volume plain = makeSynthetic("phantom", 32);
    Volume turned = plain;
    const glm::dmat3 R = rotation({1, 2, 3}, 25);
    turned.direction = R;
    REQUIRE(turned.rotated());
    RenderSettings s;
    s.threads = 2;
    s.camera.width = s.camera.height = 40;
    const Scene a(plain, s), b(turned, s);
    for (Projection proj : {Projection::Orthographic, Projection::Perspective}) {
        // A free camera, and the same camera carried along by R.
        CameraParams c = s.camera;
        c.projection = proj;
        c.lookAtSet = true;
        c.eye = plain.center() + glm::dvec3(70, -50, 30);
        c.lookAt = plain.center();
        c.upHint = {0, 0.3, 1};
        CameraParams cr = c;
        cr.eye = R * c.eye;
        cr.lookAt = R * c.lookAt;
        cr.upHint = R * c.upHint;
        for (RendererKind r : kRenderers) {
            INFO(toString(r) << (proj == Projection::Perspective ? " perspective" : " ortho"));
            const Image ia = a.render(r, c), ib = b.render(r, cr);
            REQUIRE(maxValue(ia) > 0.1);
            CHECK(maxAbsDiff(ia, ib) < 1e-5);
        }
    }
    // The orbit: a turn of the volume by t about world z is a turn of the azimuth by t.
    Volume spun = plain;
    spun.direction = rotation({0, 0, 1}, 40);
    const Scene c(spun, s);
    CameraParams orbit = s.camera;
    orbit.azimuthDeg = 10;
    orbit.elevationDeg = 25;
    CameraParams turnedOrbit = orbit;
    turnedOrbit.azimuthDeg = 50;
    for (RendererKind r : kRenderers) {
        INFO(toString(r) << " orbit");
        const Image ia = a.render(r, orbit), ic = c.render(r, turnedOrbit);
        CHECK(maxAbsDiff(ia, ic) < 1e-5);
        // ... and not the image of the unturned view (the check can fail).
        CHECK(maxAbsDiff(ia, c.render(r, orbit)) > 0.05);
    }
}

TEST_CASE("oblique: x-ray of an off-centre ball in an oblique grid is its world chord length",
          "[oblique][accuracy]") {
    // The same ball axis-aligned and in an oblique grid (25 degrees about (1, 2, 3), origin
    // moved): the oblique image must match the chord lengths through the ball's world
    // position as well as the axis-aligned one does, in every renderer. Dropping the rotation
    // moves the ball by 15 voxels here and fails the check.
    const glm::dvec3 c(14, 21, 12);
    const double r = 8.0;
    Volume plain = ball(c, r);
    Volume oblique = plain;
    oblique.direction = rotation({1, 2, 3}, 25);
    oblique.origin = glm::dvec3(-30, 10, -20);
    CHECK(glm::length(oblique.worldPosition(c) - (oblique.origin + c)) > 15);
    RenderSettings s;
    s.threads = 2;
    s.mode = RenderMode::Xray;
    s.camera.width = s.camera.height = 64;
    s.camera.pixelSize = 1.0;
    s.camera.azimuthDeg = 30;
    s.camera.elevationDeg = 15;
    const Scene a(plain, s), b(oblique, s);
    for (RendererKind rk : kRenderers) {
        const double ePlain = chordError(a.render(rk, s.camera), plain, s.camera, c, r);
        const double eOblique = chordError(b.render(rk, s.camera), oblique, s.camera, c, r);
        INFO(toString(rk) << ": rms relative error axis-aligned " << ePlain << ", oblique "
                          << eOblique);
        CHECK(ePlain < 0.03);
        CHECK(eOblique < 0.03);
        CHECK(eOblique < 1.5 * ePlain + 0.005);
    }
}

TEST_CASE("oblique: a NIfTI sform rotation is kept as the volume's direction", "[oblique]") {
    // splat's own writer and reader: the affine (rotation included) survives the round trip,
    // every voxel at the same world position.
    Volume v = makeSynthetic("blob", 12);
    v.direction = rotation({-1, 0.5, 2}, 17);
    v.origin = glm::dvec3(3, -4, 5);
    for (const char* ext : {".nii", ".nrrd", ".mha"}) {
        INFO(ext);
        const std::string p = (testTmpDir() / (std::string("oblique") + ext)).string();
        if (std::string(ext) == ".nii") saveNifti(p, v);
        if (std::string(ext) == ".nrrd") saveNrrd(p, v);
        if (std::string(ext) == ".mha") saveMetaImage(p, v);
        const Volume back = loadVolume(p);
        REQUIRE(back.dims == v.dims);
        double worst = 0;
        for (int k : {0, 11})
            for (int j : {0, 11})
                for (int i : {0, 11})
                    worst = std::max(worst, glm::length(back.worldPosition(glm::dvec3(i, j, k)) -
                                                        v.worldPosition(glm::dvec3(i, j, k))));
        CHECK(worst < 1e-4);
        CHECK(back.data == v.data);
    }
}

TEST_CASE("oblique: a direction that is not a rotation is refused at the boundary", "[oblique]") {
    Volume v = makeSynthetic("blob", 8);
    RenderSettings s;
    for (const glm::dmat3& bad :
         {glm::dmat3(2.0),
          glm::dmat3(glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1))}) {
        v.direction = bad;
        CHECK_THROWS_WITH(Scene(v, s), Catch::Contains("volume direction must be a rotation"));
    }
    v.direction = glm::dmat3(std::nan(""));
    CHECK_THROWS_WITH(Scene(v, s), Catch::Contains("volume direction must be a rotation"));
}
