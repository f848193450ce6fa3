#pragma once
// The journal of a resumable command (popping's frames, study's measured points): a hidden
// folder in the report folder that holds the work done so far, so that `--resume` after an
// interruption does only the rest (docs/reliability.md).
#include <CLI/CLI.hpp>
#include <filesystem>

namespace splat::cli {

/// Creates the journal folder `dir`. What it holds is kept only with `resume` and when it
/// was made by the same command (its scene, less the options that do not change results:
/// --resume, --quiet, --threads, ...); else it is emptied (with a warning under --resume).
void prepareJournal(const CLI::App& cmd, const std::filesystem::path& dir, bool resume);

/// Removes the journal once the report it served is written.
void removeJournal(const std::filesystem::path& dir);

}  // namespace splat::cli
