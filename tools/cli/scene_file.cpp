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

/// A path as the scene says it, relative to the scene file's folder.
std::string resolvedPath(const Entry& e, const std::string& value, const fs::path& dir) {
    if (value.empty() || value.rfind("synthetic:", 0) == 0) return value;
    if (e.key == "tf" && isTransferPreset(value)) return value;
    const fs::path p(value);
    return p.is_absolute() ? value : (dir / p).lexically_normal().string();
}

/// A path as a written scene holds it: absolute.
std::string absolutePath(const Entry& e, const std::string& value) {
    if (value.empty() || value.rfind("synthetic:", 0) == 0) return value;
    if (e.key == "tf" && isTransferPreset(value)) return value;
    std::error_code ec;
    const fs::path a = fs::absolute(value, ec);
    return ec ? value : a.lexically_normal().string();
}

char separatorOf(const std::string& key) { return key == "size" || key == "dims" ? 'x' : ','; }

const char* jsonType(const json& v) {
    if (v.is_boolean()) return "a boolean";
    if (v.is_number()) return "a number";
    if (v.is_string()) return "a string";
    if (v.is_array()) return "an array";
    if (v.is_object()) return "an object";
    return "null";
}

/// The command line's text for one scalar or list value of `key`.
std::string textOf(const Entry& e, const json& v, const std::string& where, const fs::path& dir) {
    switch (e.kind) {
        case ValueKind::Flag:
            if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
            if (v.is_string() && (v == "true" || v == "false")) return v.get<std::string>();
            throw UsageError(where + " must be true or false, not " + jsonType(v));
        case ValueKind::Integer:
        case ValueKind::Unsigned: {
            if (v.is_number_integer() || v.is_number_unsigned()) {
                if (e.kind == ValueKind::Unsigned && v.is_number_integer() &&
                    v.get<long long>() < 0)
                    throw UsageError(where + " must be an integer >= 0 (got " + v.dump() + ")");
                return v.dump();
            }
            if (v.is_number_float()) {
                const double d = v.get<double>();
                if (!std::isfinite(d) || d != std::floor(d) || std::abs(d) > 9.2e18)
                    throw UsageError(where + " must be an integer (got " + v.dump() + ")");
                char buf[32];
                std::snprintf(buf, sizeof buf, "%.0f", d);
                return buf;
            }
            if (v.is_string()) return v.get<std::string>();
            throw UsageError(where + " must be an integer, not " + jsonType(v));
        }
        case ValueKind::Real:
            if (v.is_number()) return v.dump();
            if (v.is_string()) return v.get<std::string>();
            throw UsageError(where + " must be a number, not " + jsonType(v));
        case ValueKind::Text:
        case ValueKind::TextList:
            if (v.is_string())
                return e.path != PathKind::None ? resolvedPath(e, v.get<std::string>(), dir)
                                                : v.get<std::string>();
            if (v.is_number()) return v.dump();
            if (v.is_array()) {
                std::string s;
                for (const json& item : v) {
                    if (!item.is_number() && !item.is_string())
                        throw UsageError(where + " must be a string or an array of numbers");
                    if (!s.empty()) s += separatorOf(e.key);
                    s += item.is_string() ? item.get<std::string>() : item.dump();
                }
                return s;
            }
            throw UsageError(where + " must be a string" +
                             std::string(e.kind == ValueKind::TextList ? " or an array" : "") +
                             ", not " + jsonType(v));
    }
    return {};
}

const char* kindWord(ValueKind k) {
    switch (k) {
        case ValueKind::Integer:
            return "integer in range";
        case ValueKind::Unsigned:
            return "non-negative integer in range";
        case ValueKind::Real:
            return "number";
        case ValueKind::Flag:
            return "boolean";
        default:
            return "value";
    }
}

void applyKey(const CLI::App& cmd, CommandTable& t, Entry& e, const json& v,
              const std::string& file, const fs::path& dir) {
    const std::string where = file + ": \"" + e.key + "\"";
    if (e.opt->count() > 0) return;  // the flag given on the command line wins
    if (v.is_object()) {
        if (!e.setObject) throw UsageError(where + " must not be an object");
        e.setObject(v);
        t.sceneKeys.insert(e.key);
        return;
    }
    std::vector<std::string> results;
    // A repeatable option takes an array of values; an array of numbers is one value.
    const bool each = e.kind == ValueKind::TextList && v.is_array() &&
                      !std::all_of(v.begin(), v.end(), [](const json& i) { return i.is_number(); });
    if (e.kind == ValueKind::TextList && v.is_array() && v.empty()) {
        t.sceneKeys.insert(e.key);
        return;
    }
    if (each) {
        for (const json& item : v) results.push_back(textOf(e, item, where, dir));
    } else if (v.is_array() && e.kind != ValueKind::Text && e.kind != ValueKind::TextList) {
        throw UsageError(where + " must be " +
                         (e.kind == ValueKind::Flag ? std::string("true or false")
                                                    : std::string("a ") + kindWord(e.kind)) +
                         ", not an array");
    } else {
        results.push_back(textOf(e, v, where, dir));
    }
    if (results.empty()) return;
    if (e.check)
        for (const std::string& r : results)
            if (const std::string why = e.check(r); !why.empty())
                throw UsageError(where + ": " + v.dump() + " is not a valid " + kindWord(e.kind) +
                                 " (--" + e.key + ": " + why + ")");
    e.opt->add_result(results);
    try {
        e.opt->run_callback();
    } catch (const CLI::Error& err) {
        throw UsageError(where + ": " + v.dump() + " is not a valid " + kindWord(e.kind) + " (" +
                         err.what() + ")");
    }
    (void)cmd;
    t.sceneKeys.insert(e.key);
}

/// The volume's keys may be grouped: "volume": {"path": ..., "dims": ..., ...}.
constexpr const char* kVolumeKeys[] = {"dims",       "type",         "spacing",
                                       "big-endian", "header-bytes", "nan-policy"};

void applyScene(const CLI::App& cmd, CommandTable& t, const std::string& file) {
    std::ifstream in(file);
    if (!in) throw Error(file + ": cannot open scene file");
    json j;
    try {
        j = json::parse(in);
    } catch (const json::exception& e) {
        throw UsageError(file + ": not valid JSON (" + std::string(e.what()) + ")");
    }
    if (!j.is_object()) throw UsageError(file + ": a scene file must be a JSON object");
    const fs::path dir = fs::absolute(file).parent_path();
    std::vector<std::pair<std::string, json>> items;
    for (auto& [key, value] : j.items()) {
        if (key == "command") {
            if (!value.is_string()) throw UsageError(file + ": \"command\" must be a string");
            continue;
        }
        if (key == "volume" && value.is_object()) {
            for (auto& [k, v] : value.items()) {
                const std::string& name = k;  // (clang 14 cannot capture a structured binding)
                const bool known =
                    k == "path" || std::any_of(std::begin(kVolumeKeys), std::end(kVolumeKeys),
                                               [&](const char* n) { return name == n; });
                if (!known)
                    throw UsageError(file + ": unknown scene key 'volume." + k +
                                     "' (path, dims, type, spacing, big-endian, header-bytes, "
                                     "nan-policy)");
                items.emplace_back(k == "path" ? "volume" : k, v);
            }
            continue;
        }
        items.emplace_back(key, value);
    }
    std::vector<std::string> elsewhere;
    for (auto& [key, value] : items) {
        if (Entry* e = find(t, key)) {
            applyKey(cmd, t, *e, value, file, dir);
            continue;
        }
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

/// A text value as a written scene holds it: numbers and lists of numbers typed.
json typedText(const std::string& key, const std::string& s) {
    if (s.empty()) return s;
    std::vector<double> v;
    std::size_t start = 0;
    const char sep = separatorOf(key);
    while (true) {
        std::size_t end = s.find(sep, start);
        if (sep == 'x' && end == std::string::npos) end = s.find('X', start);
        const std::string item = s.substr(start, end == std::string::npos ? end : end - start);
        char* stop = nullptr;
        const double d = std::strtod(item.c_str(), &stop);
        if (item.empty() || *stop != '\0' || !std::isfinite(d) ||
            item.find_first_not_of("0123456789+-.eE") != std::string::npos)
            return s;
        v.push_back(d);
        if (end == std::string::npos) break;
        start = end + 1;
    }
    json out = json::array();
    for (double d : v)
        out.push_back(d == std::floor(d) && std::abs(d) < 1e15 ? json(std::int64_t(d)) : json(d));
    return v.size() == 1 ? out[0] : out;
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

namespace {

ValueKind kindOf(OptionType t) {
    switch (t) {
        case OptionType::Flag:
            return ValueKind::Flag;
        case OptionType::Integer:
            return ValueKind::Integer;
        case OptionType::Unsigned:
            return ValueKind::Unsigned;
        case OptionType::Real:
            return ValueKind::Real;
        case OptionType::TextList:
            return ValueKind::TextList;
        case OptionType::Text:
            break;
    }
    return ValueKind::Text;
}

PathKind pathOf(OptionPath p) {
    return p == OptionPath::Input ? PathKind::Input
                                  : p == OptionPath::Output ? PathKind::Output : PathKind::None;
}

/// A number option's text as a written scene holds it: typed (the text itself when it is
/// not a number; such a value never runs).
json typedNumber(OptionType type, const std::string& text) {
    char* end = nullptr;
    if (type == OptionType::Real) {
        const double d = std::strtod(text.c_str(), &end);
        return !text.empty() && *end == '\0' ? json(d) : json(text);
    }
    const long long i = std::strtoll(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0') return json(text);
    return type == OptionType::Unsigned && i >= 0 ? json(static_cast<unsigned long long>(i))
                                                  : json(i);
}

}  // namespace

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
                get = [&slot, type = spec->type] { return typedNumber(type, slot); };
            }
        }
        o->group(std::string(spec->group));
        detail::recordOption(cmd, o, kindOf(spec->type), pathOf(spec->path), std::move(get));
        tableOf(cmd).entries.back().check = [spec](const std::string& text) {
            return checkOptionText(*spec, text);
        };
    }
}

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

void prepareCommand(CLI::App& cmd, std::initializer_list<const char*> required) {
    CommandTable& t = tableOf(cmd);
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
    CommandTable& t = tableOf(cmd);
    nlohmann::ordered_json j, volume;
    j["command"] = cmd.get_name();
    auto put = [&](const std::string& key, const json& v) {
        const auto o = nlohmann::ordered_json::parse(v.dump());
        if (key == "volume")
            volume["path"] = o;
        else if (std::any_of(std::begin(kVolumeKeys), std::end(kVolumeKeys),
                             [&](const char* k) { return key == k; }))
            volume[key] = o;
        else
            j[key] = o;
        if (key == "volume") j["volume"] = nullptr;  // keeps its place before the others
    };
    for (const Entry& e : t.entries) {
        if (e.getObject) {
            json o = e.getObject();
            if (!o.is_null()) {
                put(e.key, o);
                continue;
            }
        }
        json v = e.get();
        if (e.kind == ValueKind::Text) {
            std::string s = v.get<std::string>();
            if (e.path != PathKind::None) s = absolutePath(e, s);
            v = typedText(e.key, s);
        } else if (e.kind == ValueKind::TextList) {
            json list = json::array();
            for (const json& item : v) list.push_back(typedText(e.key, item.get<std::string>()));
            v = list;
        }
        put(e.key, v);
    }
    if (!volume.empty()) j["volume"] = volume;
    return j;
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
            values.push_back(e.path != PathKind::None ? absolutePath(e, s) : s);
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
