// The option table (splat/options.h): its defaults are the library's defaults, and for every
// option the command-line flag, the scene-file key and the library's reading of the value
// (what a Python keyword calls) accept and refuse the same values with the same line (a scene
// value of the wrong type also names the file and the key).
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "splat/options.h"
#include "splat/scene_file.h"

using namespace splat;
using namespace splat::test;

namespace {

// What the library says about `value` for option `o`: "" accepted, else its error line.
// Volume options load a small synthetic volume; sweep options read a popping sweep.
std::string libraryVerdict(const OptionSpec& o, const std::string& value) {
    OptionValues values(kVolumeOptions | kRenderOptions | kImageOptions | kSweepOptions);
    try {
        values.set(o.name, value);
        if (o.set == kVolumeOptions) {
            loadVolumeFrom("synthetic:phantom:8", values);
            return "";
        }
        values.set("size", "8x8");
        if (o.name == "size") values.set("size", value);
        RenderUse use;
        use.imageExt = ".exr";
        use.oneRenderer = o.set != kSweepOptions;
        const RenderSettings s = renderSettingsFrom(values, use, [](const std::string&) {});
        if (o.set == kSweepOptions) {
            Sweep sweep;
            PoppingOptions p;
            poppingFrom(values, s, sweep, p);
        }
        return "";
    } catch (const Error& e) {
        return e.what();
    }
}

// Values to try: the default, and values the option's type or checks refuse.
std::vector<std::string> trialValues(const OptionSpec& o) {
    std::vector<std::string> v;
    if (!o.defaultText.empty()) v.emplace_back(o.defaultText);
    switch (o.type) {
        case OptionType::Flag:
            v.emplace_back("true");
            break;
        case OptionType::Real:
            v.insert(v.end(), {"abc", "1e999"});
            break;
        case OptionType::Integer:
            v.insert(v.end(), {"1.5", "100000"});
            break;
        case OptionType::Unsigned:
            v.emplace_back("-1");
            break;
        case OptionType::Text:
        case OptionType::TextList:
            // A file name is resolved against a scene file's folder: only non-paths here.
            if (o.path == OptionPath::None) v.emplace_back("?");
            break;
    }
    return v;
}

std::string lastErrorLine(const RunResult& r) {
    const std::vector<std::string> lines = r.errLines();
    return lines.empty() ? "" : lines.back();
}

}  // namespace

TEST_CASE("the option table's defaults are the library's defaults", "[options]") {
    for (const OptionSpec& o : optionTable()) {
        INFO(o.name);
        // Every option once: entries share a name only when no command takes both.
        CHECK(findOption(o.name, o.set) == &o);
        for (const OptionSpec& other : optionTable())
            if (&other != &o && other.name == o.name) CHECK((other.set & o.set) == 0);
        CHECK(!o.help.empty());
        CHECK(!o.group.empty());
        CHECK(checkOptionText(o, std::string(o.defaultText.empty() && o.type != OptionType::Text &&
                                                     o.type != OptionType::TextList
                                                 ? (o.type == OptionType::Flag ? "false" : "0")
                                                 : o.defaultText))
                  .empty());
    }
    const OptionValues values(kRenderOptions | kImageOptions);
    const RenderSettings s = parseRenderOptions(values), d;
    CHECK(s.renderer == d.renderer);
    CHECK(s.mode == d.mode);
    CHECK(s.order == d.order);
    CHECK(s.classification == d.classification);
    CHECK(s.camera.width == 512);
    CHECK(s.camera.height == 512);
    CHECK(s.camera.projection == d.camera.projection);
    CHECK(s.camera.fovDeg == d.camera.fovDeg);
    CHECK(s.kernel == d.kernel);
    CHECK(s.quality.slab == d.quality.slab);
    CHECK(s.quality.earlyTermination == d.quality.earlyTermination);
    CHECK(s.quality.referenceTolerance == d.quality.referenceTolerance);
    CHECK(s.quality.tileSize == d.quality.tileSize);
    CHECK(s.quality.lod == d.quality.lod);
    CHECK(s.quality.ewa == d.quality.ewa);
    CHECK(s.quality.pixelFilter == d.quality.pixelFilter);
    CHECK(s.shading.ambient == d.shading.ambient);
    CHECK(s.shading.diffuse == d.shading.diffuse);
    CHECK(s.shading.specular == d.shading.specular);
    CHECK(s.shading.shininess == d.shading.shininess);
    CHECK(s.shading.headlight);
    CHECK(s.isoLevel == 0.5);
    CHECK(s.isoNormalized);
    CHECK(s.background == d.background);
    const LoadOptions load = loadOptionsFrom(OptionValues(kVolumeOptions)), dl;
    CHECK(load.nonFinite == dl.nonFinite);
    CHECK(load.raw.headerBytes == dl.raw.headerBytes);
    CHECK(load.allowOutsideDataFiles == dl.allowOutsideDataFiles);
}

TEST_CASE("a malformed value names its flag in one line", "[options]") {
    OptionValues values(kRenderOptions);
    CHECK_THROWS_WITH(values.set("slab", "abc"), "--slab: 'abc' is not a number");
    CHECK_THROWS_WITH(values.set("tile-size", "1.5"), "--tile-size: '1.5' is not an integer");
    CHECK_THROWS_WITH(values.set("no-such", "1"), "unknown option --no-such");
    values.set("tile-size", "4");
    CHECK_THROWS_WITH(parseRenderOptions(values), "--tile-size must be between 8 and 32");
    // Early termination tracks a tile in at most 64 blocks of 4x4 pixels: 32 is the largest
    // tile the compositor takes, so the option refuses 33 and 64 before a render starts.
    for (const char* tile : {"33", "64"}) {
        values.set("tile-size", tile);
        CHECK_THROWS_WITH(parseRenderOptions(values), "--tile-size must be between 8 and 32");
    }
    values.set("tile-size", "32");
    CHECK_NOTHROW(parseRenderOptions(values));
}

TEST_CASE("flag, scene key and library accept and refuse the same values alike",
          "[options][cli][scene]") {
    const auto dir = testTmpDir("options_walk");
    const std::string out = (dir / "x.exr").string(), scene = (dir / "scene.json").string();
    int refused = 0;
    for (const OptionSpec& o : optionTable()) {
        if (o.set == kStudyOnlyOptions) continue;  // no flag: swept by a study only
        if (!(o.set & kSharedOptions)) continue;    // a command's own: walked below
        for (const std::string& value : trialValues(o)) {
            const std::string name(o.name);
            INFO("--" << name << " " << value);
            const std::string verdict = libraryVerdict(o, value);
            // The sweep's runs are long; a refusal is what they are compared on.
            if (o.set == kSweepOptions && verdict.empty()) continue;
            std::vector<std::string> base;
            if (o.set == kSweepOptions)
                base = {"popping",  "synthetic:phantom:8", "--size", "8x8",
                        "--report", dir.string()};
            else
                base = {"render", "synthetic:phantom:8", "-o", out};
            if (name != "size" && o.set != kSweepOptions)
                base.insert(base.end(), {"--size", "8x8"});
            std::vector<std::string> flag = base;
            if (o.type == OptionType::Flag)
                flag.push_back("--" + name);
            else
                flag.insert(flag.end(), {"--" + name, value});
            nlohmann::json j = {{"command", base[0]}};
            j[name] = o.type == OptionType::Flag ? nlohmann::json(true) : nlohmann::json(value);
            std::ofstream(scene) << j.dump();
            std::vector<std::string> fromScene = base;
            fromScene.insert(fromScene.end(), {"--scene", scene});
            const RunResult a = runSplat(flag), b = runSplat(fromScene);
            INFO(a.err << b.err);
            // The library's reading of the scene file (what Python's splat.load_scene and
            // splat.render_scene call) says what the command line's --scene says.
            std::string sceneVerdict;
            try {
                const SceneFile file = readSceneFile(scene);
                REQUIRE(file.entries.size() == 1);
                REQUIRE(file.entries[0].texts.size() == 1);
                sceneVerdict = libraryVerdict(o, file.entries[0].texts[0]);
            } catch (const Error& e) {
                sceneVerdict = e.what();
            }
            if (verdict.empty()) {
                CHECK(a.status == 0);
                CHECK(b.status == 0);
                CHECK(sceneVerdict.empty());
                continue;
            }
            CHECK(lastErrorLine(b) == "splat: error: " + sceneVerdict);
            ++refused;
            CHECK(a.status == b.status);
            CHECK(a.status != 0);
            CHECK(lastErrorLine(a) == "splat: error: " + verdict);
            // A scene file's value of the wrong type also names the file and the key.
            const std::string sceneLine = lastErrorLine(b);
            CHECK(sceneLine.find(verdict) != std::string::npos);
            if (sceneLine != "splat: error: " + verdict) {
                CHECK(sceneLine.find(scene) != std::string::npos);
                CHECK(sceneLine.find("\"" + name + "\"") != std::string::npos);
            }
        }
    }
    CHECK(refused > 40);
}

namespace {

// A command's run with `extra` after `base` (the pairs of `base` naming `drop` left out).
std::vector<std::string> commandLine(const std::vector<std::string>& base, const std::string& drop,
                                     const std::vector<std::string>& extra) {
    std::vector<std::string> args;
    for (std::size_t i = 0; i < base.size(); ++i) {
        if (base[i] == "--" + drop) {
            ++i;
            continue;
        }
        args.push_back(base[i]);
    }
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
}

// Walks the options of `sets` (a command's own) on `base`: a value the table refuses is
// refused by the flag and the scene key, exit 2, with the same "--NAME: why"; the default
// runs; text the command itself checks gets the same line from the flag and the key (only
// refusals when `refusalsOnly`: the command's runs are long). `scene` "": the command reads no
// scene file (the view commands), only its flags are walked.
void walkCommandOptions(unsigned sets, const std::vector<std::string>& base,
                        const std::string& scene, int& refused, int& same,
                        bool refusalsOnly = false) {
    for (const OptionSpec* o : optionsOf(sets)) {
        CHECK(findOption(o->name, sets) == o);
        if (o->type == OptionType::Flag || o->path != OptionPath::None) continue;
        for (const std::string& value : trialValues(*o)) {
            const std::string name(o->name), why = checkOptionText(*o, value);
            INFO(base[0] << " --" << name << " " << value);
            // A value the table accepts runs only when it is the default or text the command
            // itself checks (a number like 100000 frames would be a long run).
            if (why.empty() && value != o->defaultText && o->type != OptionType::Text) continue;
            if (why.empty() && refusalsOnly) continue;
            const RunResult a = runSplat(commandLine(base, name, {"--" + name, value}));
            INFO(a.err);
            if (scene.empty()) {
                if (!why.empty()) {
                    ++refused;
                    CHECK(a.status == 2);
                    CHECK(lastErrorLine(a) == "splat: error: --" + name + ": " + why);
                } else if (value == o->defaultText) {
                    CHECK(a.status == 0);
                } else {  // text the command refuses, in one line of its own
                    ++same;
                    CHECK(a.status != 0);
                    CHECK(a.errLines().size() == 1);
                }
                continue;
            }
            nlohmann::json j = {{"command", base[0]}};
            j[name] = value;
            std::ofstream(scene) << j.dump();
            const RunResult b = runSplat(commandLine(base, name, {"--scene", scene}));
            INFO(b.err);
            CHECK(a.status == b.status);
            if (!why.empty()) {
                ++refused;
                const std::string verdict = "--" + name + ": " + why;
                CHECK(a.status == 2);
                CHECK(lastErrorLine(a) == "splat: error: " + verdict);
                const std::string sceneLine = lastErrorLine(b);
                CHECK(sceneLine.find(verdict) != std::string::npos);
                CHECK(sceneLine.find(scene) != std::string::npos);
                CHECK(sceneLine.find("\"" + name + "\"") != std::string::npos);
            } else if (value == o->defaultText) {
                CHECK(a.status == 0);
            } else {  // text the command refuses: the same line from the flag and the key
                ++same;
                CHECK(a.status != 0);
                CHECK(lastErrorLine(a) == lastErrorLine(b));
            }
        }
    }
}

}  // namespace

TEST_CASE("the commands' own options: flag and scene key accept and refuse alike, in one line",
          "[options][cli][scene]") {
    const auto dir = testTmpDir("options_walk_commands");
    const std::string scene = (dir / "scene.json").string(), curve = (dir / "curve.json").string();
    std::ofstream(curve) << R"({"points": [[-2, 0, 0], [2, 0, 0]]})";
    const std::string in = "synthetic:phantom:8";
    int refused = 0, same = 0;
    walkCommandOptions(kRotateOptions,
                       {"rotate", in, "--size", "8x8", "--frames", "2", "-q", "--overwrite", "-o",
                        (dir / "frames").string()},
                       scene, refused, same);
    // The view commands read no scene file: their flags against the table.
    walkCommandOptions(kSlicesOptions | kViewOptions,
                       {"slices", in, "--every", "4", "-o", (dir / "slices").string()}, "",
                       refused, same);
    walkCommandOptions(kMprOptions,
                       {"mpr", in, "--plane", "0,0,0,0,0,1", "--size", "8x8", "-o",
                        (dir / "mpr.png").string()},
                       "", refused, same);
    walkCommandOptions(kCprOptions,
                       {"cpr", in, "--curve", curve, "--width", "8", "-o",
                        (dir / "cpr.png").string()},
                       "", refused, same);
    walkCommandOptions(kIsoOptions, {"iso", in, "--level", "0.5", "-o", (dir / "s.ply").string()},
                       "", refused, same);
    walkCommandOptions(kRenderCommandOptions,
                       {"render", in, "--size", "8x8", "-o", (dir / "r.exr").string()}, scene,
                       refused, same);
    walkCommandOptions(kBenchOptions, {"bench", in, "--size", "8x8", "--repeats", "1"}, scene,
                       refused, same);
    walkCommandOptions(kPoppingOptions,
                       {"popping", in, "--size", "8x8", "--report", (dir / "pop").string()},
                       scene, refused, same, true);
    walkCommandOptions(kStudyOptions,
                       {"study", in, "--size", "8x8", "--report", (dir / "study").string()},
                       scene, refused, same, true);
    CHECK(refused >= 30);
    CHECK(same >= 10);
}
