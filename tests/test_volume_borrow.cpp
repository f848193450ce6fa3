// Borrowed and typed volumes: a Volume over caller-owned samples of
// type u8/i16/u16/f32, read as raw * scale + offset, renders exactly as its owned float copy
// in every renderer and mode, without a float copy; the keepAlive is held; validation holds.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "splat/error.h"
#include "splat/render.h"
#include "splat/synthetic.h"

using namespace splat;

namespace {

RenderSettings small(RenderMode mode, RendererKind renderer) {
    RenderSettings s;
    s.camera.width = s.camera.height = 24;
    s.camera.azimuthDeg = 30;
    s.camera.elevationDeg = 20;
    s.threads = 2;
    s.mode = mode;
    s.renderer = renderer;
    s.transfer = TransferFunction::preset("gray-ramp");
    s.isoLevel = 0.4;
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

// int16 samples of the blob in [0, 1000], the owned float copy they stand for
// (value = raw * 0.001 - 0.25) and the borrowed volumes over both.
struct Fixture {
    static constexpr int n = 14;
    std::vector<std::int16_t> raw;
    std::vector<float> floats;
    Volume owned;
    Fixture() {
        const Volume blob = makeSynthetic("blob", n);
        raw.resize(blob.voxelCount());
        for (std::size_t q = 0; q < raw.size(); ++q)
            raw[q] = std::int16_t(std::lround(1000.0 * blob.data[q]));
        owned = makeVolume(blob.dims, glm::dvec3(1.0, 1.5, 0.75), "owned copy");
        owned.origin = glm::dvec3(-3, 2, 5);
        for (std::size_t q = 0; q < raw.size(); ++q)
            owned.data[q] = float(double(raw[q]) * 0.001 + -0.25);
        floats = owned.data;
    }
};

}  // namespace

TEST_CASE("borrow: float and int16 samples render as the owned float copy", "[borrow]") {
    Fixture f;
    const Volume bf = Volume::borrow(f.floats.data(), SampleType::Float32, f.owned.dims,
                                     f.owned.spacing, f.owned.origin);
    const Volume bi = Volume::borrow(f.raw.data(), SampleType::Int16, f.owned.dims, f.owned.spacing,
                                     f.owned.origin, nullptr, 0.001, -0.25);
    CHECK(bf.borrowed());
    CHECK(bf.data.empty());
    CHECK(bi.data.empty());
    CHECK(bi.sampleType() == SampleType::Int16);
    CHECK(bi.sampleData() == f.raw.data());
    CHECK(bf.sampleData() == f.floats.data());
    CHECK(bi.bytes() == f.raw.size() * 2);
    CHECK(f.owned.sampleType() == SampleType::Float32);
    CHECK(f.owned.sampleData() == f.owned.data.data());
    CHECK_FALSE(f.owned.borrowed());
    for (int k = 0; k < f.n; k += 3)
        for (int i = 0; i < f.n; i += 2) CHECK(bi.at(i, 5, k) == f.owned.at(i, 5, k));
    for (RenderMode mode : {RenderMode::Dvr, RenderMode::Mip, RenderMode::Xray, RenderMode::Iso})
        for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet, RendererKind::Reference}) {
            INFO("mode " << int(mode) << " renderer " << int(r));
            const RenderSettings s = small(mode, r);
            const Image expected = Scene(f.owned, s).render(s);
            const Scene sf(bf, s), si(bi, s);
            // The Scene reads the caller's samples: no float copy is made.
            CHECK(sf.volume().data.empty());
            CHECK(si.volume().sampleData() == f.raw.data());
            CHECK(sf.render(s).pixels == expected.pixels);
            CHECK(si.render(s).pixels == expected.pixels);
            CHECK(Renderer(bi, s).render().pixels == expected.pixels);
        }
}

TEST_CASE("borrow: every sample type reads raw * scale + offset", "[borrow]") {
    const std::vector<std::uint8_t> u8 = {0, 1, 127, 255, 3, 9, 200, 17};
    const std::vector<std::uint16_t> u16 = {0, 1, 65535, 40000, 3, 9, 200, 17};
    const std::vector<std::int16_t> i16 = {-32768, -1, 32767, 0, 3, -9, 200, 17};
    const std::vector<float> f32 = {-2.5f, 0.0f, 1e6f, 3.25f, 3, 9, 200, 17};
    const glm::ivec3 d(2, 2, 2);
    const Volume a = Volume::borrow(u8.data(), SampleType::UInt8, d, glm::dvec3(1), {}, {}, 2, 1);
    const Volume b = Volume::borrow(u16.data(), SampleType::UInt16, d, glm::dvec3(1), {}, {}, 0.5);
    const Volume c = Volume::borrow(i16.data(), SampleType::Int16, d, glm::dvec3(1), {}, {}, 1, -5);
    const Volume e = Volume::borrow(f32.data(), SampleType::Float32, d, glm::dvec3(1), {}, {}, 4);
    for (std::size_t q = 0; q < 8; ++q) {
        CHECK(a.value(q) == float(u8[q] * 2.0 + 1.0));
        CHECK(b.value(q) == float(u16[q] * 0.5));
        CHECK(c.value(q) == float(i16[q] - 5.0));
        CHECK(e.value(q) == float(f32[q] * 4.0));
    }
    std::vector<float> row(8);
    c.values(0, 8, row.data());
    CHECK(row[0] == -32773.0f);
    CHECK(row[2] == 32762.0f);
    CHECK(a.bytes() == 8u);
    CHECK(b.bytes() == 16u);
    CHECK(e.bytes() == 32u);
    const VolumeStats st = volumeStats(c, 4);
    CHECK(st.minValue == -32773.0f);
    CHECK(st.maxValue == 32762.0f);
    CHECK_THAT(describeVolume(a), Catch::Contains("uint8 samples, borrowed"));
}

TEST_CASE("borrow: the caller's buffer is read when a Scene is built", "[borrow]") {
    Fixture f;
    const RenderSettings s = small(RenderMode::Mip, RendererKind::Sheet);
    const Volume bi = Volume::borrow(f.raw.data(), SampleType::Int16, f.owned.dims, f.owned.spacing,
                                     f.owned.origin, nullptr, 0.001, -0.25);
    const Image before = Scene(bi, s).render(s);
    for (std::size_t q = 0; q < f.raw.size(); q += 2) f.raw[q] = std::int16_t(f.raw[q] / 2);
    const Image after = Scene(bi, s).render(s);
    CHECK(after.pixels != before.pixels);
    // The changed samples, and nothing else, made the difference.
    Volume copy = f.owned;
    for (std::size_t q = 0; q < f.raw.size(); ++q) copy.data[q] = float(f.raw[q] * 0.001 - 0.25);
    CHECK(Scene(copy, s).render(s).pixels == after.pixels);
}

TEST_CASE("borrow: the keepAlive is held by the volume and every Scene built from it", "[borrow]") {
    auto buffer = std::make_shared<std::vector<std::uint16_t>>(12 * 12 * 12, 0);
    for (std::size_t q = 0; q < buffer->size(); ++q) (*buffer)[q] = std::uint16_t(q % 97);
    const RenderSettings s = small(RenderMode::Xray, RendererKind::Axis);
    std::weak_ptr<std::vector<std::uint16_t>> watch = buffer;
    std::unique_ptr<Scene> scene;
    std::unique_ptr<Renderer> renderer;
    {
        Volume v = Volume::borrow(buffer->data(), SampleType::UInt16, glm::ivec3(12), glm::dvec3(1),
                                  glm::dvec3(0), buffer);
        CHECK(buffer.use_count() == 2);
        scene = std::make_unique<Scene>(v, s);  // by reference: the Scene keeps a copy
        renderer = std::make_unique<Renderer>(v, s);
        CHECK(buffer.use_count() >= 4);
        const Image image = scene->render(s);
        buffer.reset();  // the caller lets go; the volume and the scenes still hold it
        CHECK(watch.use_count() >= 3);
        CHECK(scene->render(s).pixels == image.pixels);
    }
    CHECK(watch.use_count() == 2);  // the Scene and the Renderer
    CHECK_FALSE(watch.expired());
    CHECK(renderer->render().pixels == scene->render(s).pixels);
    scene.reset();
    renderer.reset();
    CHECK(watch.expired());
}

TEST_CASE("borrow: bad input is one error line; NaN/Inf borrowed floats are refused", "[borrow]") {
    std::vector<float> v(8 * 8 * 8, 1.0f);
    const glm::ivec3 d(8);
    CHECK_THAT(errorOf([&] { Volume::borrow(nullptr, SampleType::Float32, d, glm::dvec3(1), {}); }),
               Catch::Contains("null"));
    CHECK_THAT(errorOf([&] {
                   Volume::borrow(v.data(), SampleType::Float32, glm::ivec3(8, 0, 8), glm::dvec3(1),
                                  {});
               }),
               Catch::Contains("invalid dimensions"));
    CHECK_THAT(errorOf([&] {
                   Volume::borrow(v.data(), SampleType::Float32, d, glm::dvec3(1, -1, 1), {});
               }),
               Catch::Contains("invalid spacing"));
    CHECK_THAT(errorOf([&] {
                   Volume::borrow(v.data(), SampleType::Float32, d, glm::dvec3(1),
                                  glm::dvec3(0, NAN, 0));
               }),
               Catch::Contains("origin"));
    CHECK_THAT(errorOf([&] {
                   Volume::borrow(v.data(), SampleType::Int16, d, glm::dvec3(1), {}, {}, INFINITY);
               }),
               Catch::Contains("scale"));
    CHECK_THAT(errorOf([&] { Volume::borrow(v.data(), SampleType(9), d, glm::dvec3(1), {}); }),
               Catch::Contains("sample type"));
    v[17] = std::numeric_limits<float>::quiet_NaN();
    v[300] = -std::numeric_limits<float>::infinity();
    const Volume b = Volume::borrow(v.data(), SampleType::Float32, d, glm::dvec3(1), {});
    const RenderSettings s = small(RenderMode::Dvr, RendererKind::Sheet);
    CHECK_THAT(errorOf([&] { Scene(b, s); }), Catch::Contains("2 NaN/Inf samples"));
    // A huge scale overflows float: the values are checked, not the raw samples.
    std::vector<std::int16_t> i(8 * 8 * 8, 30000);
    const Volume o = Volume::borrow(i.data(), SampleType::Int16, d, glm::dvec3(1), {}, {}, 1e300);
    CHECK_THAT(errorOf([&] { Scene(o, s); }), Catch::Contains("NaN/Inf samples"));
}
