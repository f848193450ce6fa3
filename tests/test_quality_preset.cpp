// The quality preset (`--quality fast|default|exact`, splat/options.h): default is the option
// table's defaults (the same settings as no preset); options given beside a preset win, a
// scene file's value only where it differs from the default; a study sweeps it as a knob; and
// the presets order the error against the reference: exact below default below fast.
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "splat/image_io.h"
#include "splat/metrics.h"
#include "splat/options.h"
#include "splat/render.h"
#include "splat/study.h"
#include "splat/synthetic.h"

using namespace splat;
using namespace splat::test;

namespace {

RenderSettings settingsOf(const std::vector<std::pair<std::string, std::string>>& given,
                          bool fromScene = false) {
    OptionValues v(kRenderOptions);
    for (const auto& [name, text] : given) v.set(name, text, fromScene);
    return parseRenderOptions(v);
}

bool sameQuality(const Quality& a, const Quality& b) {
    return a.slab == b.slab && a.earlyTermination == b.earlyTermination &&
           a.referenceStep == b.referenceStep && a.referenceTolerance == b.referenceTolerance &&
           a.factorisedSheets == b.factorisedSheets && a.warpTolerance == b.warpTolerance &&
           a.tileSize == b.tileSize && a.lod == b.lod &&
           a.ewa == b.ewa && a.pixelFilter == b.pixelFilter;
}

}  // namespace

TEST_CASE("options: --quality default is the option table's defaults", "[options][quality]") {
    const RenderSettings none = settingsOf({}), preset = settingsOf({{"quality", "default"}});
    CHECK(sameQuality(none.quality, preset.quality));
    CHECK(none.quality.earlyTermination == 1.0 / 256.0);
    CHECK(none.quality.slab == 1.0);
    CHECK(none.quality.factorisedSheets == 0);
    RenderSettings s = none;
    applyQualityPreset(s, QualityPreset::Default);
    CHECK(sameQuality(s.quality, none.quality));
}

TEST_CASE("options: a quality preset sets its knobs and options beside it win",
          "[options][quality]") {
    const RenderSettings fast = settingsOf({{"quality", "fast"}});
    const RenderSettings exact = settingsOf({{"quality", "exact"}});
    const Quality d = settingsOf({}).quality;
    CHECK(fast.quality.earlyTermination > d.earlyTermination);
    CHECK(fast.quality.slab > d.slab);
    CHECK(fast.quality.referenceTolerance > d.referenceTolerance);
    CHECK(exact.quality.earlyTermination == 0.0);
    CHECK(exact.quality.slab < d.slab);
    CHECK(exact.quality.referenceStep == 0.125);
    CHECK(exact.quality.referenceTolerance == 1e-5);
    CHECK(exact.quality.factorisedSheets == 0);
    // Given beside the preset (command line, Python keyword): that option wins, the others
    // keep the preset's values.
    const RenderSettings mixed = settingsOf({{"quality", "exact"}, {"early-termination", "0.01"}});
    CHECK(mixed.quality.earlyTermination == 0.01);
    CHECK(mixed.quality.slab == exact.quality.slab);
    // Also at the option's default value: given is given.
    const RenderSettings atDefault =
        settingsOf({{"quality", "exact"}, {"early-termination", "0.00390625"}});
    CHECK(atDefault.quality.earlyTermination == d.earlyTermination);
    // From a scene file (which holds every option): only a value other than the default wins.
    const RenderSettings scene = settingsOf(
        {{"quality", "exact"}, {"early-termination", "0.00390625"}, {"slab", "0.5"}}, true);
    CHECK(scene.quality.earlyTermination == 0.0);
    CHECK(scene.quality.slab == 0.5);
    // The values and their names.
    for (QualityPreset p : {QualityPreset::Fast, QualityPreset::Default, QualityPreset::Exact})
        CHECK(parseQualityPreset(toString(p)) == p);
    CHECK_THROWS_WITH(parseQualityPreset("best"),
                      "--quality 'best' must be fast, default or exact");
    OptionValues bad(kRenderOptions);
    bad.set("quality", "best");
    CHECK_THROWS_AS(parseRenderOptions(bad), OptionError);
}

TEST_CASE("options: a study sweeps the quality preset as a knob", "[options][quality][study]") {
    RenderSettings s = settingsOf({});
    applyKnob(s, "quality", "exact");
    CHECK(s.quality.earlyTermination == 0.0);
    applyKnob(s, "quality", "default");
    CHECK(sameQuality(s.quality, settingsOf({}).quality));
    CHECK_THROWS_AS(parseKnob("quality=fast,best"), Error);
}

TEST_CASE("options: the quality presets order the error against the reference",
          "[options][quality][accuracy]") {
    const Volume v = makeSynthetic("phantom", 32);
    RenderSettings base;
    base.transfer = TransferFunction::preset("ct-soft");
    base.camera.width = base.camera.height = 64;
    base.camera.azimuthDeg = 30;
    base.camera.elevationDeg = 15;
    base.threads = 2;
    RenderSettings truth = base;
    truth.renderer = RendererKind::Reference;
    applyQualityPreset(truth, QualityPreset::Exact);
    const Image reference = render(v, truth);
    for (RendererKind renderer : {RendererKind::Axis, RendererKind::Sheet}) {
        double error[3];
        int at = 0;
        for (QualityPreset p :
             {QualityPreset::Exact, QualityPreset::Default, QualityPreset::Fast}) {
            RenderSettings s = base;
            s.renderer = renderer;
            applyQualityPreset(s, p);
            error[at++] = compareImages(render(v, s), reference).rmse;
        }
        INFO(toString(renderer) << ": exact " << error[0] << ", default " << error[1] << ", fast "
                                << error[2]);
        // Early termination changes nothing in this translucent phantom (axis: exact equals
        // default); the slabs do (sheet).
        CHECK(error[0] <= error[1]);
        if (renderer == RendererKind::Sheet) CHECK(error[0] < error[1]);
        CHECK(error[1] < error[2]);
        // fast's factorised sheets resample on the voxel grid: at 2 pixels per voxel here
        // (measured: axis 0.0131, default 0.0010) its error grows with the magnification.
        CHECK(error[2] < 0.02);
    }
}

TEST_CASE("options: --quality on the command line and in a scene file", "[options][quality][cli]") {
    const auto dir = testTmpDir("quality_preset");
    const std::string plain = (dir / "plain.exr").string(), preset = (dir / "default.exr").string(),
                      fast = (dir / "fast.exr").string(), scene = (dir / "scene.json").string();
    const std::vector<std::string> base = {"render", "synthetic:phantom:16", "--size", "24x24"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> a = base;
        a.insert(a.end(), extra.begin(), extra.end());
        return runSplat(a);
    };
    REQUIRE(with({"-o", plain}).status == 0);
    REQUIRE(with({"--quality", "default", "-o", preset}).status == 0);
    REQUIRE(with({"--quality", "fast", "-o", fast}).status == 0);
    // default is today's image bit for bit; fast is another one.
    CHECK(compareImages(readImage(preset), readImage(plain)).maxAbs == 0.0);
    CHECK(compareImages(readImage(fast), readImage(plain)).maxAbs > 0.0);
    std::ofstream(scene) << nlohmann::json{{"quality", "fast"}}.dump();
    const std::string fromScene = (dir / "scene.exr").string();
    REQUIRE(with({"--scene", scene, "-o", fromScene}).status == 0);
    CHECK(compareImages(readImage(fromScene), readImage(fast)).maxAbs == 0.0);
    const RunResult bad = with({"--quality", "best", "-o", plain});
    CHECK(bad.status != 0);
    CHECK(bad.errLines().back() == "splat: error: --quality 'best' must be fast, default or exact");
}
