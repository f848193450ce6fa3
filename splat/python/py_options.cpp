// Keyword arguments read by the library's option table (splat/options.h): a keyword is a long
// option with '-' written '_' (`--pixel-size` -> pixel_size=), so a keyword accepts, refuses
// and means exactly what its flag does, with the same one-line messages. splat/__init__.py
// turns keyword values into the options' text (size=(512, 512) -> "512x512").
#include <cstdio>

#include "py_common.h"
#include "splat/scene_file.h"

namespace splat::python {

namespace {

/// "pixel-size" -> "pixel_size"; "from" -> "from_" (a Python keyword).
std::string keywordOf(std::string_view longName) {
    std::string k(longName);
    for (char& c : k)
        if (c == '-') c = '_';
    if (k == "from") k += "_";
    return k;
}

/// Warnings as the command line prints them, one line each on stderr.
void warnLine(const std::string& line) {
    std::fprintf(stderr, "splat: warning: %s\n", line.c_str());
}

OptionValues valuesOf(unsigned sets, const Keywords& keywords) {
    OptionValues values(sets);
    for (const auto& [name, text] : keywords) {
        if (!values.has(name))
            throw OptionError("unknown keyword '" + keywordOf(name) +
                              "' (the keywords are the command line's long options: "
                              "splat.render_options(), splat.load_options())");
        values.set(name, text);
    }
    return values;
}

OptionTableRows tableOf(unsigned sets) {
    OptionTableRows out;
    for (const OptionSpec* o : optionsOf(sets))
        out.emplace_back(keywordOf(o->name), "--" + std::string(o->name), std::string(o->help),
                         std::string(o->defaultText));
    return out;
}

}  // namespace

RenderSettings parseRenderSettings(
    const Keywords& keywords, const std::string& tfJson, const Volume* volume, bool oneRenderer,
    unsigned extraSets,
    const std::function<void(const OptionValues&, const RenderSettings&)>& readExtra) {
    OptionValues values = valuesOf(kRenderOptions | extraSets, keywords);
    values.tfInline = tfJson;
    RenderUse use;
    use.oneRenderer = oneRenderer;
    RenderSettings s = renderSettingsFrom(values, use, warnLine);
    if (readExtra) readExtra(values, s);
    if (volume)
        s = withDataDefaults(values, s, *volume, [](const std::string& line) {
            std::fprintf(stderr, "splat: %s\n", line.c_str());
        });
    return s;
}

OptionTableRows renderOptionTable() { return tableOf(kRenderOptions); }

Volume loadWithOptions(const std::string& spec, const Keywords& keywords) {
    const OptionValues values = valuesOf(kVolumeOptions, keywords);
    loadOptionsFrom(values);  // malformed options: before any reading
    py::gil_scoped_release release;
    try {
        return loadVolumeFrom(spec, values);
    } catch (const OptionError&) {
        throw;
    } catch (const Error& e) {
        rethrowFileError(e, spec, true);
    }
}

OptionTableRows loadOptionTable() { return tableOf(kVolumeOptions); }

OptionTableRows poppingOptionTable() { return tableOf(kSweepOptions); }

SceneRows readScene(const std::string& path) {
    SceneFile scene;
    try {
        scene = readSceneFile(path);
    } catch (const OptionError&) {
        throw;
    } catch (const Error& e) {
        rethrowFileError(e, path, true);
    }
    SceneRows rows;
    std::get<0>(rows) = scene.command;
    for (const SceneEntry& e : scene.entries)
        std::get<1>(rows).emplace_back(e.key == "volume" ? e.key : keywordOf(e.key), e.texts,
                                       e.object);
    std::get<2>(rows) = scene.otherKeys;
    return rows;
}

void writeScene(const std::string& path, const std::string& command, const std::string& volume,
                const Keywords& keywords, const std::string& tfJson) {
    const unsigned sets = command == "render"    ? kVolumeOptions | kRenderOptions | kImageOptions
                          : command == "popping" ? kVolumeOptions | kRenderOptions | kSweepOptions
                                                 : kVolumeOptions | kRenderOptions;
    const OptionValues values = valuesOf(sets, keywords);
    std::vector<std::pair<std::string, std::string>> scene;
    scene.emplace_back("volume", sceneValueJson("volume", *tableSceneKey("volume"), {volume}));
    for (const OptionSpec* spec : values.specs()) {
        const std::string name(spec->name);
        if (name == "tf" && !tfJson.empty()) {
            scene.emplace_back(name, tfJson);
            continue;
        }
        const SceneKey how = *tableSceneKey(name);
        std::vector<std::string> texts;
        if (spec->type == OptionType::TextList)
            texts = values.list(name);
        else if (spec->type == OptionType::Flag)
            texts = {values.flag(name) ? "true" : "false"};
        else
            texts = {values.text(name)};
        scene.emplace_back(name, sceneValueJson(name, how, texts));
    }
    try {
        writeSceneFile(path, command, scene);
    } catch (const Error& e) {
        rethrowFileError(e, path, false);
    }
}

}  // namespace splat::python
