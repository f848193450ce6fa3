// Journals of resumable commands (see resume_journal.h).
#include "resume_journal.h"

#include <fstream>
#include <nlohmann/json.hpp>

#include "diagnostics.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/error.h"

namespace splat::cli {

namespace fs = std::filesystem;

namespace {
/// What the journal's work depends on: the scene less the run-control options.
std::string journalKey(const CLI::App& cmd) {
    nlohmann::ordered_json scene = sceneOf(cmd);
    for (const char* k :
         {"resume", "overwrite", "quiet", "threads", "parallel-frames", "scene", "write-scene"})
        scene.erase(k);
    return scene.dump();
}
}  // namespace

void prepareJournal(const CLI::App& cmd, const fs::path& dir, bool resume) {
    const std::string key = journalKey(cmd);
    const fs::path keyFile = dir / "key.json";
    std::error_code ec;
    bool same = false;
    if (std::ifstream in(keyFile); in) {
        const std::string old{std::istreambuf_iterator<char>(in), {}};
        same = old == key + "\n";
    }
    if (fs::exists(dir, ec) && !(resume && same)) {
        if (resume) warn(dir.string() + " was made by other settings; starting over");
        fs::remove_all(dir, ec);
        if (ec) throw Error(dir.string() + ": cannot clear the journal (" + ec.message() + ")");
    }
    fs::create_directories(dir, ec);
    std::error_code ignored;
    if (!fs::is_directory(dir, ignored))
        throw Error(dir.string() + ": cannot create the journal folder (" +
                    (ec ? ec.message() : std::string("not a folder")) + ")");
    removeStaleTemporaries(dir);
    if (!same || !resume) writeTextAtomic(keyFile, key + "\n");
}

void removeJournal(const fs::path& dir) {
    std::error_code ec;
    fs::remove_all(dir, ec);
}

}  // namespace splat::cli
