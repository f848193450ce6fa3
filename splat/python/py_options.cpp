// Keyword arguments read by the library's option table (splat/options.h): a keyword is a long
// option with '-' written '_' (`--pixel-size` -> pixel_size=), so a keyword accepts, refuses
// and means exactly what its flag does, with the same one-line messages. splat/__init__.py
// turns keyword values into the options' text (size=(512, 512) -> "512x512").
#include <cstdio>

#include "py_common.h"

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

}  // namespace splat::python
