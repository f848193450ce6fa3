#pragma once
// Subcommands of the `splat` program. Each registers itself on the CLI11 app and sets a
// callback; the callbacks throw splat::Error on bad input (UsageError for malformed
// options, diagnostics.h), and main() turns that into one line on stderr and the exit
// status 1 or 2.
#include <CLI/CLI.hpp>
#include <string>

namespace splat::cli {

void registerInfo(CLI::App& app);        // cmd_info.cpp
void registerRender(CLI::App& app);      // cmd_render.cpp
void registerRotate(CLI::App& app);      // cmd_rotate.cpp
void registerCompare(CLI::App& app);     // cmd_compare.cpp
void registerBench(CLI::App& app);       // cmd_bench.cpp
void registerPopping(CLI::App& app);     // cmd_popping.cpp
void registerStudy(CLI::App& app);       // cmd_study.cpp
void registerSlices(CLI::App& app);      // cmd_slices.cpp
void registerMpr(CLI::App& app);         // cmd_mpr.cpp
void registerCpr(CLI::App& app);         // cmd_cpr.cpp
void registerIso(CLI::App& app);         // cmd_iso.cpp
void registerCompletion(CLI::App& app);  // cmd_completion.cpp (hidden)
void registerGaussians(CLI::App& app);   // cmd_gaussians.cpp

/// The command line as typed (for reports that say how to reproduce them).
const std::string& commandLine();
void setCommandLine(int argc, char** argv);
/// `arg` quoted for a POSIX shell when it needs to be.
std::string shellQuoted(const std::string& arg);

/// --version: the version from the build, the compiler and the SIMD inner loops.
std::string versionText();

}  // namespace splat::cli
