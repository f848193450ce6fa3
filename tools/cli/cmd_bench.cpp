// TEMPORARY placeholder while the renderer is written.
#include "commands.h"
namespace splat::cli {
void registerBench(CLI::App&) {}
}  // namespace splat::cli
