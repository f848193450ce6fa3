// Scene files read and written from the option table (see splat/scene_file.h).
#include "splat/scene_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/transfer.h"

namespace splat {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// The volume's reading options, which a scene may group under "volume".
constexpr const char* kVolumeKeys[] = {"dims",       "type",         "spacing",
                                       "big-endian", "header-bytes", "nan-policy"};

bool isVolumeKey(std::string_view key) {
    return std::any_of(std::begin(kVolumeKeys), std::end(kVolumeKeys),
                       [&](const char* k) { return key == k; });
}

bool isTransferPreset(const std::string& name) {
    const std::vector<std::string> presets = TransferFunction::presetNames();
    return std::find(presets.begin(), presets.end(), name) != presets.end();
}

char separatorOf(std::string_view key) { return key == "size" || key == "dims" ? 'x' : ','; }

const char* jsonType(const json& v) {
    if (v.is_boolean()) return "a boolean";
    if (v.is_number()) return "a number";
    if (v.is_string()) return "a string";
    if (v.is_array()) return "an array";
    if (v.is_object()) return "an object";
    return "null";
}

/// A path as the scene says it, relative to the scene file's folder.
std::string resolvedPath(std::string_view key, const std::string& value, const fs::path& dir) {
    if (value.empty() || isGeneratedInput(value)) return value;
    if (key == "tf" && isTransferPreset(value)) return value;
    const fs::path p(value);
    return p.is_absolute() ? value : (dir / p).lexically_normal().string();
}

/// An integer value's text: JSON integers, and numbers with no fraction.
std::string integerText(const SceneKey& how, const json& v, const std::string& where) {
    if (v.is_number_integer() || v.is_number_unsigned()) {
        if (how.type == OptionType::Unsigned && v.is_number_integer() && v.get<long long>() < 0)
            throw OptionError(where + " must be an integer >= 0 (got " + v.dump() + ")");
        return v.dump();
    }
    if (v.is_number_float()) {
        const double d = v.get<double>();
        if (!std::isfinite(d) || d != std::floor(d) || std::abs(d) > 9.2e18)
            throw OptionError(where + " must be an integer (got " + v.dump() + ")");
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.0f", d);
        return buf;
    }
    if (v.is_string()) return v.get<std::string>();
    throw OptionError(where + " must be an integer, not " + jsonType(v));
}

/// A text value's text: strings (paths resolved), numbers, arrays of numbers joined.
std::string textText(std::string_view key, const SceneKey& how, const json& v,
                     const std::string& where, const fs::path& dir) {
    if (v.is_string())
        return how.path != OptionPath::None ? resolvedPath(key, v.get<std::string>(), dir)
                                            : v.get<std::string>();
    if (v.is_number()) return v.dump();
    if (v.is_array()) {
        std::string s;
        for (const json& item : v) {
            if (!item.is_number() && !item.is_string())
                throw OptionError(where + " must be a string or an array of numbers");
            if (!s.empty()) s += separatorOf(key);
            s += item.is_string() ? item.get<std::string>() : item.dump();
        }
        return s;
    }
    throw OptionError(where + " must be a string" +
                      std::string(how.type == OptionType::TextList ? " or an array" : "") +
                      ", not " + jsonType(v));
}

/// The command line's text for one scalar or list value of `key`.
std::string textOf(std::string_view key, const SceneKey& how, const json& v,
                   const std::string& where, const fs::path& dir) {
    switch (how.type) {
        case OptionType::Flag:
            if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
            if (v.is_string() && (v == "true" || v == "false")) return v.get<std::string>();
            throw OptionError(where + " must be true or false, not " + jsonType(v));
        case OptionType::Integer:
        case OptionType::Unsigned:
            return integerText(how, v, where);
        case OptionType::Real:
            if (v.is_number()) return v.dump();
            if (v.is_string()) return v.get<std::string>();
            throw OptionError(where + " must be a number, not " + jsonType(v));
        case OptionType::Text:
        case OptionType::TextList:
            return textText(key, how, v, where, dir);
    }
    return {};
}

/// One key's entry: its value's texts, checked by the option table when `how` says so.
SceneEntry entryOf(const std::string& key, const SceneKey& how, const json& v,
                   const std::string& file, const fs::path& dir) {
    const std::string where = file + ": \"" + key + "\"";
    SceneEntry e;
    e.key = key;
    e.json = v.dump();
    if (!how.read) return e;
    if (v.is_object()) {
        e.object = v.dump();
        return e;
    }
    // A repeatable option takes an array of values; an array of numbers is one value.
    const bool list = how.type == OptionType::TextList && v.is_array();
    const bool each =
        list && !std::all_of(v.begin(), v.end(), [](const json& i) { return i.is_number(); });
    if (list && v.empty()) return e;
    if (each) {
        for (const json& item : v) e.texts.push_back(textOf(key, how, item, where, dir));
    } else if (v.is_array() && how.type != OptionType::Text && !list) {
        throw OptionError(where + " must be " +
                          (how.type == OptionType::Flag
                               ? std::string("true or false")
                               : std::string("a ") + sceneKindWord(how.type)) +
                          ", not an array");
    } else {
        e.texts.push_back(textOf(key, how, v, where, dir));
    }
    if (const OptionSpec* spec = !how.checked ? nullptr : how.spec ? how.spec : findOption(key))
        for (const std::string& text : e.texts)
            if (const std::string why = checkOptionText(*spec, text); !why.empty())
                throw OptionError(where + ": " + e.json + " is not a valid " +
                                  sceneKindWord(how.type) + " (--" + key + ": " + why + ")");
    return e;
}

json parsedFile(const std::string& file) {
    std::ifstream in(file);
    if (!in) throw Error(file + ": cannot open scene file");
    json j;
    try {
        j = json::parse(in);
    } catch (const json::exception& e) {
        throw OptionError(file + ": not valid JSON (" + std::string(e.what()) + ")");
    }
    if (!j.is_object()) throw OptionError(file + ": a scene file must be a JSON object");
    return j;
}

/// The file's keys with the "volume" group flattened ("path" -> "volume").
std::vector<std::pair<std::string, json>> flatKeys(const json& j, const std::string& file,
                                                   std::string& command) {
    std::vector<std::pair<std::string, json>> items;
    for (auto& [key, value] : j.items()) {
        if (key == "command") {
            if (!value.is_string()) throw OptionError(file + ": \"command\" must be a string");
            command = value.get<std::string>();
            continue;
        }
        if (key == "volume" && value.is_object()) {
            for (auto& [k, v] : value.items()) {
                if (k != "path" && !isVolumeKey(k))
                    throw OptionError(file + ": unknown scene key 'volume." + k +
                                      "' (path, dims, type, spacing, big-endian, header-bytes, "
                                      "nan-policy)");
                items.emplace_back(k == "path" ? "volume" : k, v);
            }
            continue;
        }
        items.emplace_back(key, value);
    }
    return items;
}

/// A text value as a written scene holds it: numbers and lists of numbers typed.
json typedText(std::string_view key, const std::string& s) {
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

/// A number option's text as a written scene holds it: typed (the text itself when it is not
/// a number; such a value never runs).
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

std::optional<SceneKey> tableSceneKey(std::string_view key) {
    if (key == "volume") return SceneKey{OptionType::Text, OptionPath::Input, false, true};
    const OptionSpec* spec = findOption(key);
    if (!spec) return std::nullopt;
    return SceneKey{spec->type, spec->path, true, true};
}

const char* sceneKindWord(OptionType type) {
    switch (type) {
        case OptionType::Integer:
            return "integer in range";
        case OptionType::Unsigned:
            return "non-negative integer in range";
        case OptionType::Real:
            return "number";
        case OptionType::Flag:
            return "boolean";
        default:
            return "value";
    }
}

bool isGeneratedInput(std::string_view spec) {
    return spec.rfind("synthetic:", 0) == 0 || spec.rfind("gaussians:", 0) == 0;
}

std::string absoluteScenePath(std::string_view key, const std::string& value) {
    if (value.empty() || isGeneratedInput(value)) return value;
    if (key == "tf" && isTransferPreset(value)) return value;
    std::error_code ec;
    const fs::path a = fs::absolute(value, ec);
    return ec ? value : a.lexically_normal().string();
}

SceneFile readSceneFile(const std::string& path, const SceneKeyLookup& lookup) {
    const json j = parsedFile(path);
    SceneFile scene;
    scene.path = path;
    const fs::path dir = fs::absolute(path).parent_path();
    for (auto& [key, value] : flatKeys(j, path, scene.command)) {
        if (const std::optional<SceneKey> how = lookup(key))
            scene.entries.push_back(entryOf(key, *how, value, path, dir));
        else
            scene.otherKeys.push_back(key);
    }
    return scene;
}

std::string sceneValueJson(std::string_view key, const SceneKey& how,
                           const std::vector<std::string>& texts) {
    auto one = [&](const std::string& text) -> json {
        switch (how.type) {
            case OptionType::Flag:
                return text == "true";
            case OptionType::Integer:
            case OptionType::Unsigned:
            case OptionType::Real:
                return typedNumber(how.type, text);
            default:
                return typedText(
                    key, how.path != OptionPath::None ? absoluteScenePath(key, text) : text);
        }
    };
    if (how.type == OptionType::TextList) {
        json list = json::array();
        for (const std::string& t : texts) list.push_back(one(t));
        return list.dump();
    }
    return one(texts.empty() ? std::string() : texts.front()).dump();
}

std::string sceneText(const std::string& command,
                      const std::vector<std::pair<std::string, std::string>>& values) {
    nlohmann::ordered_json j, volume;
    j["command"] = command;
    for (const auto& [key, text] : values) {
        const auto v = nlohmann::ordered_json::parse(text);
        if (key == "volume") {
            volume["path"] = v;
            j["volume"] = nullptr;  // keeps its place before the others
        } else if (isVolumeKey(key)) {
            volume[key] = v;
        } else {
            j[key] = v;
        }
    }
    if (!volume.empty()) j["volume"] = volume;
    return j.dump(2) + "\n";
}

void writeSceneFile(const std::string& path, const std::string& command,
                    const std::vector<std::pair<std::string, std::string>>& values) {
    writeTextAtomic(path, sceneText(command, values));
}

}  // namespace splat
