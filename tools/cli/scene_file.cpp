// Scene files: options recorded per subcommand, read from and written to JSON (see
// scene_file.h).
#include "scene_file.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "commands.h"
#include "diagnostics.h"
#include "splat/atomic_file.h"
#include "splat/transfer.h"
#include "splat/version.h"

namespace splat::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Entry {
    std::string key;
    CLI::Option* opt = nullptr;
    ValueKind kind = ValueKind::Text;
    PathKind path = PathKind::None;
    std::function<json()> get;
    json initial;  ///< the value at registration: the default
    std::function<void(const json&)> setObject;
    std::function<json()> getObject;
    /// An option of the library's table: why a value's text is not of its type ("" if it is).
    std::function<std::string(const std::string&)> check;
    const OptionSpec* spec = nullptr;  ///< its entry
};

struct CommandTable {
    std::vector<Entry> entries;
    std::set<std::string> sceneKeys;  ///< keys whose value came from the scene file
    std::string scene, writeScene;    ///< --scene, --write-scene
    nlohmann::ordered_json fixed;     ///< the scene fixed by beginRun
};

std::map<const CLI::App*, CommandTable>& tables() {
    static std::map<const CLI::App*, CommandTable> t;
    return t;
}

CommandTable& tableOf(const CLI::App& cmd) { return tables()[&cmd]; }

Entry* find(CommandTable& t, const std::string& key) {
    for (Entry& e : t.entries)
        if (e.key == key) return &e;
    return nullptr;
}

std::string keyOf(const CLI::Option* o) {
    if (!o->get_lnames().empty()) return o->get_lnames()[0];
    std::string k = o->get_name();
    for (char& c : k) c = char(std::tolower(static_cast<unsigned char>(c)));
    return k;
}

/// How the library reads `e`'s scene value (splat/scene_file.h).
SceneKey sceneKeyOf(const Entry& e) {
    return SceneKey{e.kind, e.path, bool(e.check), e.opt->count() == 0, e.spec};
}

void applyEntry(CommandTable& t, Entry& e, const SceneEntry& value, const std::string& file) {
    const std::string where = file + ": \"" + e.key + "\"";
    if (e.opt->count() > 0) return;  // the flag given on the command line wins
    if (!value.object.empty()) {
        if (!e.setObject) throw UsageError(where + " must not be an object");
        e.setObject(json::parse(value.object));
        t.sceneKeys.insert(e.key);
        return;
    }
    if (value.texts.empty()) {  // an empty array of a repeatable option
        t.sceneKeys.insert(e.key);
        return;
    }
    e.opt->add_result(value.texts);
    try {
        e.opt->run_callback();
    } catch (const CLI::Error& err) {
        throw UsageError(where + ": " + value.json + " is not a valid " + sceneKindWord(e.kind) +
                         " (" + err.what() + ")");
    }
    t.sceneKeys.insert(e.key);
}

void applyScene(const CLI::App& cmd, CommandTable& t, const std::string& file) {
    const SceneFile scene = asOptionUsage([&] {
        return readSceneFile(file, [&](std::string_view key) -> std::optional<SceneKey> {
            const Entry* e = find(t, std::string(key));
            if (!e) return std::nullopt;
            return sceneKeyOf(*e);
        });
    });
    for (const SceneEntry& value : scene.entries) applyEntry(t, *find(t, value.key), value, file);
    std::vector<std::string> elsewhere;
    for (const std::string& key : scene.otherKeys) {
        bool other = false;
        for (auto& [app, table] : tables())
            if (app != &cmd && find(table, key)) other = true;
        if (!other) throw UsageError(file + ": unknown scene key '" + key + "'");
        elsewhere.push_back(key);
    }
    if (!elsewhere.empty()) {
        std::string list;
        for (const std::string& k : elsewhere) list += (list.empty() ? "" : ", ") + k;
        warn(file + ": keys of other commands, ignored by '" + cmd.get_name() + "': " + list);
    }
}

}  // namespace

namespace detail {
void recordOption(CLI::App& cmd, CLI::Option* opt, ValueKind kind, PathKind path,
                  std::function<json()> get) {
    Entry e;
    e.key = keyOf(opt);
    e.opt = opt;
    e.kind = kind;
    e.path = path;
    e.get = std::move(get);
    e.initial = e.get();
    tableOf(cmd).entries.push_back(std::move(e));
}
}  // namespace detail

CLI::Option* addFlag(CLI::App& cmd, const std::string& names, bool& var, const std::string& help,
                     const std::string& group) {
    CLI::Option* o = cmd.add_flag(names, var, help)->group(group);
    detail::recordOption(cmd, o, ValueKind::Flag, PathKind::None, [&var] { return json(var); });
    return o;
}

void addTableOptions(CLI::App& cmd, OptionValues& values, unsigned sets) {
    for (const OptionSpec* spec : optionsOf(sets)) {
        const std::string name(spec->name), flag = "--" + name, help(spec->help);
        CLI::Option* o = nullptr;
        std::function<json()> get;
        if (spec->type == OptionType::Flag) {
            bool& slot = values.flagSlot(name);
            o = cmd.add_flag(flag, slot, help);
            get = [&slot] { return json(slot); };
        } else if (spec->type == OptionType::TextList) {
            std::vector<std::string>& slot = values.listSlot(name);
            o = cmd.add_option(flag, slot, help);
            get = [&slot] { return json(slot); };
        } else {
            std::string& slot = values.textSlot(name);
            o = cmd.add_option(flag, slot, help);
            if (!spec->defaultText.empty()) o->default_str(std::string(spec->defaultText));
            if (spec->type == OptionType::Text) {
                get = [&slot] { return json(slot); };
            } else {
                // The library refuses negative counts: --help says so as CLI11's check would.
                o->type_name(spec->type == OptionType::Unsigned ? std::string("UINT:NONNEGATIVE")
                                                                : std::string(typeName(spec->type)));
                get = [&slot, spec] {
                    return json::parse(sceneValueJson(spec->name, {spec->type}, {slot}));
                };
            }
        }
        o->group(std::string(spec->group));
        detail::recordOption(cmd, o, spec->type, spec->path, std::move(get));
        tableOf(cmd).entries.back().check = [spec](const std::string& text) {
            return checkOptionText(*spec, text);
        };
        tableOf(cmd).entries.back().spec = spec;
    }
}

namespace detail {
const OptionSpec& tableEntry(std::string_view name, unsigned sets, OptionType type) {
    const OptionSpec* spec = findOption(name, sets);
    if (!spec) throw std::logic_error("no option --" + std::string(name) + " in the table");
    if (spec->type != type)
        throw std::logic_error("--" + std::string(name) + " is bound to a variable of another type");
    return *spec;
}

std::string flagNames(const OptionSpec& spec) {
    const std::string flag = "--" + std::string(spec.name);
    return spec.shortName.empty() ? flag : "-" + std::string(spec.shortName) + "," + flag;
}

void checkedByTable(CLI::App& cmd, CLI::Option* o, const OptionSpec& spec) {
    if (!spec.defaultText.empty() && o->get_default_str() != spec.defaultText)
        throw std::logic_error("--" + std::string(spec.name) + ": the default " +
                               o->get_default_str() + " is not the table's " +
                               std::string(spec.defaultText));
    if (spec.type != OptionType::Flag && spec.type != OptionType::Text &&
        spec.type != OptionType::TextList)
        o->check(CLI::Validator(
            [&spec](std::string& text) -> std::string {
                // Thrown past CLI11, as the table's other options are refused: one line
                // "--NAME: why", the line a scene key's value gets in brackets.
                if (const std::string why = checkOptionText(spec, text); !why.empty())
                    throw OptionError("--" + std::string(spec.name) + ": " + why);
                return {};
            },
            ""));
    Entry& e = tableOf(cmd).entries.back();
    e.check = [&spec](const std::string& text) { return checkOptionText(spec, text); };
    e.spec = &spec;
}
}  // namespace detail

void readGiven(const CLI::App& cmd, OptionValues& values) {
    for (const OptionSpec* spec : values.specs())
        if (given(cmd, std::string(spec->name)))
            values.markGiven(spec->name, fromScene(cmd, std::string(spec->name)));
    values.sceneFile = sceneFileOf(cmd);
}

void acceptObject(CLI::App& cmd, const std::string& key, std::function<void(const json&)> set,
                  std::function<json()> get) {
    Entry* e = find(tableOf(cmd), key);
    if (!e) throw std::logic_error("acceptObject: no option " + key);
    e->setObject = std::move(set);
    e->getObject = std::move(get);
}

bool given(const CLI::App& cmd, const std::string& key) {
    CommandTable& t = tableOf(cmd);
    if (t.sceneKeys.count(key)) return true;
    const Entry* e = find(t, key);
    return e && e->opt->count() > 0;
}

bool fromScene(const CLI::App& cmd, const std::string& key) {
    return tableOf(cmd).sceneKeys.count(key) > 0;
}

std::string sceneFileOf(const CLI::App& cmd) { return tableOf(cmd).scene; }

void addSceneOptions(CLI::App& cmd) {
    CommandTable& t = tableOf(cmd);
    cmd.add_option("--scene", t.scene,
                   "scene FILE.json holding any of these options by their long names (flags "
                   "given override it; relative paths are relative to its folder)")
        ->group("Scene");
    cmd.add_option("--write-scene", t.writeScene,
                   "write the scene that reproduces this run (every option explicit, paths "
                   "absolute) to FILE.json")
        ->group("Scene");
}

/// A VOLUME ending in .json names a scene file (`splat render scene.json`): it becomes --scene
/// (unless --scene is given), and VOLUME then comes from the scene's "volume".
void volumeAsScene(CommandTable& t) {
    Entry* e = find(t, "volume");
    if (!e || !t.scene.empty() || e->opt->count() == 0) return;
    const std::string spec = e->get().get<std::string>();
    if (spec.size() < 5 || lowerExtension(spec) != ".json") return;
    t.scene = spec;
    e->opt->clear();
}

void prepareCommand(CLI::App& cmd, std::initializer_list<const char*> required) {
    CommandTable& t = tableOf(cmd);
    volumeAsScene(t);
    if (!t.scene.empty()) applyScene(cmd, t, t.scene);
    for (const char* key : required)
        if (!given(cmd, key)) {
            const Entry* e = find(t, key);
            const std::string flag =
                e && !e->opt->get_lnames().empty() ? "--" + std::string(key) : std::string(key);
            throw UsageError("'" + cmd.get_name() + "' needs " +
                             (std::string(key) == "volume" ? std::string("VOLUME") : flag) +
                             " (on the command line, or \"" + key + "\" in a --scene file)");
        }
    if (!t.writeScene.empty()) checkOutputFile(t.writeScene, "--write-scene");
}

bool isTransferPreset(const std::string& name) {
    for (const std::string& p : TransferFunction::presetNames())
        if (p == name) return true;
    return false;
}

void checkOutputFile(const std::string& path, const std::string& flag) {
    std::error_code ec;
    const fs::path p(path), parent = p.parent_path();
    if (fs::is_directory(p, ec))
        throw Error(path + ": " + flag + " needs a file name, not a folder");
    if (!parent.empty() && !fs::is_directory(parent, ec))
        throw Error(path + ": folder '" + parent.string() + "' does not exist");
}

nlohmann::ordered_json sceneOf(const CLI::App& cmd) {
    std::vector<std::pair<std::string, std::string>> values;
    for (const Entry& e : tableOf(cmd).entries) {
        if (e.getObject) {
            const json o = e.getObject();
            if (!o.is_null()) {
                values.emplace_back(e.key, o.dump());
                continue;
            }
        }
        const json v = e.get();
        if (e.kind == ValueKind::Text)
            values.emplace_back(e.key,
                                sceneValueJson(e.key, sceneKeyOf(e), {v.get<std::string>()}));
        else if (e.kind == ValueKind::TextList)
            values.emplace_back(
                e.key, sceneValueJson(e.key, sceneKeyOf(e), v.get<std::vector<std::string>>()));
        else
            values.emplace_back(e.key, v.dump());
    }
    return nlohmann::ordered_json::parse(sceneText(cmd.get_name(), values));
}

// Options that steer a run but not what its files hold: left out of the metadata, so a
// frame rendered by `--resume` is byte-identical to one from an uninterrupted run.
static bool isRunControl(const std::string& key) { return key == "resume" || key == "overwrite"; }

std::string canonicalCommand(const CLI::App& cmd) {
    CommandTable& t = tableOf(cmd);
    std::string line = "splat " + cmd.get_name();
    for (const Entry& e : t.entries) {
        if (isRunControl(e.key)) continue;
        if (e.getObject && !e.getObject().is_null()) {
            line += " --" + e.key + " " + shellQuoted("<inline in splat:scene>");
            continue;
        }
        const json v = e.get();
        if (v == e.initial) continue;
        std::vector<std::string> values;
        if (e.kind == ValueKind::Flag) {
            line += " --" + e.key + (v.get<bool>() ? "" : "=false");
            continue;
        }
        if (e.kind == ValueKind::TextList) {
            for (const json& item : v) values.push_back(item.get<std::string>());
        } else if (v.is_string()) {
            const std::string s = v.get<std::string>();
            values.push_back(e.path != PathKind::None ? absoluteScenePath(e.key, s) : s);
        } else {
            values.push_back(v.dump());
        }
        const bool positional = e.opt->get_lnames().empty() && e.opt->get_snames().empty();
        for (const std::string& s : values)
            line += (positional ? " " : " --" + e.key + " ") + shellQuoted(s);
    }
    return line;
}

void beginRun(const CLI::App& cmd) {
    CommandTable& t = tableOf(cmd);
    t.fixed = sceneOf(cmd);
    auto scene = t.fixed;
    for (const char* k : {"resume", "overwrite"}) scene.erase(k);
    runMetadata() = {{"Software", std::string("splat ") + kVersion},
                     {"splat:command", canonicalCommand(cmd)},
                     {"splat:scene", scene.dump()},
                     // No time stamp (OpenEXR writes one by default): a scene reproduces
                     // its images byte for byte.
                     {"DateTime", ""}};
}

void forgetCommand(const CLI::App& cmd) { tables().erase(&cmd); }

std::vector<std::pair<std::string, std::string>>& runMetadata() {
    static std::vector<std::pair<std::string, std::string>> m;
    return m;
}

WriteOptions withMetadata(WriteOptions o) {
    for (const auto& kv : runMetadata()) o.metadata.push_back(kv);
    return o;
}

void finishRun(const CLI::App& cmd) {
    CommandTable& t = tableOf(cmd);
    if (t.writeScene.empty()) return;
    writeTextAtomic(t.writeScene, t.fixed.dump(2) + "\n");
    std::printf("wrote scene %s\n", t.writeScene.c_str());
}

std::vector<std::string> recordedKeys(const CLI::App& cmd) {
    std::vector<std::string> keys;
    for (const Entry& e : tableOf(cmd).entries) keys.push_back(e.key);
    return keys;
}

}  // namespace splat::cli
