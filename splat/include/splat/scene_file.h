#pragma once
// Scene files (docs/command-line.md "Scene files"): one JSON object holding a run's options by
// their long names ("pixel-size": 0.5), "volume" for the input (a volume, or a Gaussian scene:
// a .ply file or gaussians:NAME) and optionally "command". The volume's reading options may be
// grouped: "volume": {"path": ..., "dims": ..., ...}. Read and written here for the command
// line and the Python module alike: each value becomes the option's text as the command line
// would take it (typed JSON numbers, arrays and booleans, or the command line's strings;
// relative paths resolved against the file's folder), checked by the option table, so a scene
// key accepts and refuses what its flag and its Python keyword do, with the same message.
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "splat/options.h"

namespace splat {

/// How a scene key's value reads: its type, whether it is a path, whether the option table
/// checks its text (false for options a command registers itself), and whether it is read at
/// all (false: a flag given on the command line overrides it; its entry holds no value).
struct SceneKey {
    OptionType type = OptionType::Text;
    OptionPath path = OptionPath::None;
    bool checked = false;
    bool read = true;
    /// The entry that checks the value (null: the shared option named like the key).
    const OptionSpec* spec = nullptr;
};
/// The SceneKey of `key`, or nothing for a key the reader does not know.
using SceneKeyLookup = std::function<std::optional<SceneKey>(std::string_view key)>;
/// The option table's keys (checked) and "volume" (an input path).
std::optional<SceneKey> tableSceneKey(std::string_view key);

/// One key of a scene file, as its option reads it.
struct SceneEntry {
    std::string key;
    /// The value as the option's text: one per item of a repeatable option's array (none for
    /// an empty array), else one.
    std::vector<std::string> texts;
    /// An object value (an inline transfer function) as JSON text; texts is then empty.
    std::string object;
    /// The value as the file holds it (JSON text), for messages.
    std::string json;
};

struct SceneFile {
    std::string path;
    std::string command;                 ///< "command" ("" when the file has none)
    std::vector<SceneEntry> entries;     ///< the keys `lookup` knows, in file order
    std::vector<std::string> otherKeys;  ///< the keys it does not know, in file order
};

/// Reads a scene file. Throws splat::Error when it cannot be opened, OptionError "FILE: why"
/// for malformed JSON, a value of the wrong JSON type or (checked keys) a value its option
/// refuses: "FILE: \"KEY\": VALUE is not a valid KIND (--KEY: why)".
SceneFile readSceneFile(const std::string& path, const SceneKeyLookup& lookup = tableSceneKey);

/// The words a message uses for a value of `type`: "number", "integer in range", ...
const char* sceneKindWord(OptionType type);

/// True for an input that names no file: synthetic:NAME, gaussians:NAME.
bool isGeneratedInput(std::string_view spec);
/// A path as a written scene holds it: absolute (generated inputs and transfer-function
/// presets unchanged).
std::string absoluteScenePath(std::string_view key, const std::string& value);

/// A value as a written scene holds it (JSON text): numbers and lists of numbers typed
/// ("512x512" -> [512,512], "0.5" -> 0.5), paths absolute, a repeatable option an array.
std::string sceneValueJson(std::string_view key, const SceneKey& how,
                           const std::vector<std::string>& texts);

/// A scene's JSON text: {"command": COMMAND, "volume": {"path": ..., reading options},
/// KEY: VALUE, ...} from (key, JSON text) pairs in their order ("volume" is the input).
std::string sceneText(const std::string& command,
                      const std::vector<std::pair<std::string, std::string>>& values);
/// Writes sceneText to `path` atomically (splat/atomic_file.h); throws splat::Error.
void writeSceneFile(const std::string& path, const std::string& command,
                    const std::vector<std::pair<std::string, std::string>>& values);

}  // namespace splat
