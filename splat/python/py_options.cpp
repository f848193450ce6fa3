// Keyword arguments read by the command line's own option definitions (tools/cli): a
// keyword is a long option with '-' written '_' (`--pixel-size` -> pixel_size=), so a keyword
// accepts, refuses and means exactly what its flag does, with the same one-line messages.
// splat/__init__.py turns keyword values into flag text (size=(512, 512) -> "512x512").
// The CLI11 app is short-lived and built with the GIL held (the option tables are global).
#include <CLI/CLI.hpp>

#include "diagnostics.h"
#include "py_common.h"
#include "render_options.h"
#include "scene_file.h"
#include "volume_options.h"

namespace splat::python {

namespace {

/// Forgets the app's recorded options when the parse is over (scene_file.h).
struct CommandScope {
    CLI::App app{"splat"};
    ~CommandScope() { cli::forgetCommand(app); }
};

/// "--pixel-size" -> "pixel_size"; "from" -> "from_" (a Python keyword).
std::string keywordOf(const std::string& longName) {
    std::string k = longName;
    for (char& c : k)
        if (c == '-') c = '_';
    if (k == "from") k += "_";
    return k;
}

/// CLI11's wording ("The following argument was not expected: --foo") in keyword terms.
std::string keywordMessage(const CLI::ParseError& e) {
    std::string m = e.what();
    for (std::size_t at = 0; (at = m.find("--", at)) != std::string::npos;) {
        std::size_t end = at + 2;
        while (end < m.size() &&
               (std::isalnum(static_cast<unsigned char>(m[end])) || m[end] == '-'))
            ++end;
        const std::string k = keywordOf(m.substr(at + 2, end - at - 2));
        m.replace(at, end - at, k + "=");
        at += k.size() + 1;
    }
    return "unknown or malformed keyword: " + m;
}

void parse(CLI::App& app, const std::vector<std::string>& argv) {
    for (const std::string& a : argv) {
        if (a == "--") break;
        if (a.rfind("--", 0) == 0 && !app.get_option_no_throw(a))
            throw cli::UsageError("unknown keyword '" + keywordOf(a.substr(2)) +
                                  "' (the keywords are the command line's long options: "
                                  "splat.render_options(), splat.load_options())");
    }
    std::vector<std::string> reversed(argv.rbegin(), argv.rend());
    try {
        app.parse(reversed);
    } catch (const CLI::ParseError& e) {
        throw cli::UsageError(keywordMessage(e));
    }
}

std::vector<std::tuple<std::string, std::string, std::string, std::string>> tableOf(
    const CLI::App& app) {
    std::vector<std::tuple<std::string, std::string, std::string, std::string>> out;
    for (const CLI::Option* o : app.get_options()) {
        if (o->get_lnames().empty()) continue;
        const std::string name = o->get_lnames().front();
        if (name == "help" || name == "write-scene") continue;
        out.emplace_back(keywordOf(name), "--" + name, o->get_description(), o->get_default_str());
    }
    return out;
}

}  // namespace

RenderSettings parseRenderSettings(
    const std::vector<std::string>& argv, const std::string& tfJson, const Volume* volume,
    bool oneRenderer, const std::function<void(CLI::App&)>& addExtra,
    const std::function<void(const CLI::App&, const RenderSettings&)>& readExtra) {
    CommandScope scope;
    cli::RenderArgs args;
    cli::addRenderOptions(scope.app, args, false);
    if (addExtra) addExtra(scope.app);
    if (!tfJson.empty()) args.tfInline = nlohmann::json::parse(tfJson);
    parse(scope.app, argv);
    cli::prepareCommand(scope.app, {});
    cli::RenderUse use;
    use.oneRenderer = oneRenderer;
    RenderSettings s = cli::settingsFromArgs(args, use);
    if (readExtra) readExtra(scope.app, s);
    if (volume) s = cli::withDataDefaults(args, s, *volume);
    return s;
}

std::vector<std::tuple<std::string, std::string, std::string, std::string>> renderOptionTable() {
    CommandScope scope;
    cli::RenderArgs args;
    cli::addRenderOptions(scope.app, args, false);
    return tableOf(scope.app);
}

Volume loadWithOptions(const std::string& spec, const std::vector<std::string>& argv) {
    cli::VolumeArgs args;
    {
        CommandScope scope;
        cli::addVolumeOptions(scope.app, args);
        std::vector<std::string> all = argv;
        all.push_back("--");
        all.push_back(spec);
        parse(scope.app, all);
        cli::loadOptionsFromArgs(args);  // malformed options: before any reading
    }
    py::gil_scoped_release release;
    try {
        return cli::loadVolumeWith(args);
    } catch (const cli::UsageError&) {
        throw;
    } catch (const Error& e) {
        rethrowFileError(e, spec, true);
    }
}

std::vector<std::tuple<std::string, std::string, std::string, std::string>> loadOptionTable() {
    CommandScope scope;
    cli::VolumeArgs args;
    cli::addVolumeOptions(scope.app, args);
    return tableOf(scope.app);
}

}  // namespace splat::python
