#pragma once
// Options of a subcommand, remembered so that a scene file can hold every one of them
// (docs/command-line.md "Scene files", docs/decisions.md): a scene key is an option's long name
// without dashes ("pixel-size", "output"; "volume" for the VOLUME argument). The library reads
// and writes scene files (splat/scene_file.h): reading turns each key's value into the
// option's text, checked by the option table, and feeds it to its option through CLI11's own
// conversion, so a scene accepts exactly what the command line accepts; a flag given on the
// command line overrides its key. Writing a scene (--write-scene, and the metadata of every
// image) records every option's value as the command ran, paths absolute. A VOLUME ending in
// .json is a scene file (`splat render scene.json`).
#include <CLI/CLI.hpp>
#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string_view>
#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "splat/image_io.h"
#include "splat/options.h"
#include "splat/scene_file.h"

namespace splat::cli {

/// How a scene file's value becomes the option's text (splat/scene_file.h).
using ValueKind = OptionType;
/// Paths are resolved against the scene file's folder and written absolute.
using PathKind = OptionPath;

namespace detail {
void recordOption(CLI::App& cmd, CLI::Option* opt, ValueKind kind, PathKind path,
                  std::function<nlohmann::json()> get);
template <class T>
constexpr ValueKind valueKindOf() {
    if constexpr (std::is_same_v<T, bool>)
        return ValueKind::Flag;
    else if constexpr (std::is_integral_v<T> && std::is_unsigned_v<T>)
        return ValueKind::Unsigned;
    else if constexpr (std::is_integral_v<T>)
        return ValueKind::Integer;
    else if constexpr (std::is_floating_point_v<T>)
        return ValueKind::Real;
    else if constexpr (std::is_same_v<T, std::vector<std::string>>)
        return ValueKind::TextList;
    else
        return ValueKind::Text;
}
}  // namespace detail

/// An option bound to `var`, shown in `group` of --help with its default, and recorded for
/// scene files.
template <class T>
CLI::Option* addOption(CLI::App& cmd, const std::string& names, T& var, const std::string& help,
                       const std::string& group, PathKind path = PathKind::None) {
    CLI::Option* o = cmd.add_option(names, var, help)->group(group);
    if constexpr (std::is_arithmetic_v<T>) o->capture_default_str();
    if constexpr (std::is_same_v<T, std::string>)
        if (!var.empty()) o->capture_default_str();
    detail::recordOption(cmd, o, detail::valueKindOf<T>(), path,
                         [&var] { return nlohmann::json(var); });
    return o;
}

CLI::Option* addFlag(CLI::App& cmd, const std::string& names, bool& var, const std::string& help,
                     const std::string& group);

namespace detail {
/// The entry `name` of `sets`; throws std::logic_error when there is none or its type is not
/// `type` (a registration that disagrees with the table).
const OptionSpec& tableEntry(std::string_view name, unsigned sets, OptionType type);
/// "-o,--output" for the entry's flag names.
std::string flagNames(const OptionSpec& spec);
/// Shows the entry's default in --help (std::logic_error when the bound variable's default
/// differs) and checks values with the table: a flag's value before CLI11 converts it, a
/// scene key's by the library's reader, with the same message.
void checkedByTable(CLI::App& cmd, CLI::Option* o, const OptionSpec& spec);
}  // namespace detail

/// The option `name` of `sets` (OptionSet bits) from the library's option table, bound to
/// `var`: flag names, help text, --help group, default, type and path come from the entry.
template <class T>
CLI::Option* addTableOption(CLI::App& cmd, std::string_view name, T& var, unsigned sets) {
    const OptionSpec& spec = detail::tableEntry(name, sets, detail::valueKindOf<T>());
    CLI::Option* o = nullptr;
    if constexpr (std::is_same_v<T, bool>)
        o = addFlag(cmd, detail::flagNames(spec), var, std::string(spec.help),
                    std::string(spec.group));
    else
        o = addOption(cmd, detail::flagNames(spec), var, std::string(spec.help),
                      std::string(spec.group), spec.path);
    detail::checkedByTable(cmd, o, spec);
    return o;
}

/// The options of `sets` (OptionSet bits) from the library's option table, in its order:
/// each bound to its slot in `values`, shown in its --help group with its default, and
/// recorded for scene files (numbers written typed).
void addTableOptions(CLI::App& cmd, OptionValues& values, unsigned sets);
/// Marks in `values` the options given on the command line or by the scene file, and names
/// the scene file (for messages about an inline transfer function).
void readGiven(const CLI::App& cmd, OptionValues& values);

/// A key whose scene value may also be a JSON object (e.g. an inline transfer function):
/// `set` takes the object, `get` returns it for written scenes (null: the option's value).
void acceptObject(CLI::App& cmd, const std::string& key,
                  std::function<void(const nlohmann::json&)> set,
                  std::function<nlohmann::json()> get);

/// True when the option was given on the command line or by the scene file.
bool given(const CLI::App& cmd, const std::string& key);
/// True when the option's value came from the scene file rather than the command line.
bool fromScene(const CLI::App& cmd, const std::string& key);
/// The scene file being read ("" without --scene).
std::string sceneFileOf(const CLI::App& cmd);

/// --scene FILE and --write-scene FILE (group "Scene").
void addSceneOptions(CLI::App& cmd);

/// First step of a command: reads --scene (if given) into the options, then refuses a
/// missing required value (UsageError naming its flag and scene key).
void prepareCommand(CLI::App& cmd, std::initializer_list<const char*> required);

/// The scene of the command as it runs: {"command": NAME, "volume": {"path": ..., ...},
/// key: value, ...} in the order of --help.
nlohmann::ordered_json sceneOf(const CLI::App& cmd);

/// Fixes the scene for this run (call once the options are final): the metadata every
/// written image carries and what --write-scene writes.
void beginRun(const CLI::App& cmd);
/// The command line equivalent to the scene: every option that differs from its default,
/// paths absolute (the same for a run from flags and one from its written scene).
std::string canonicalCommand(const CLI::App& cmd);
/// `o` plus this run's metadata: Software, splat:command (canonicalCommand), splat:scene.
WriteOptions withMetadata(WriteOptions o);
/// The key/value pairs every image of this run records (set when the command line is read).
std::vector<std::pair<std::string, std::string>>& runMetadata();
/// Writes --write-scene FILE (if given) with the scene fixed by beginRun.
void finishRun(const CLI::App& cmd);

/// True for the names of the transfer-function presets.
bool isTransferPreset(const std::string& name);

/// Refuses, before any work, an output file name that is a folder or whose folder does not
/// exist (splat::Error naming `flag`).
void checkOutputFile(const std::string& path, const std::string& flag);

/// Drops what was recorded for `cmd` (its options and scene); call before destroying a
/// CLI::App that is not the program's own (the Python module parses each call's keyword
/// arguments with a short-lived one, splat/python/py_options.cpp).
void forgetCommand(const CLI::App& cmd);

/// Every subcommand's recorded option keys (for shell completion).
std::vector<std::string> recordedKeys(const CLI::App& cmd);

}  // namespace splat::cli
