// TEMPORARY placeholder while the renderer is written.
#include "commands.h"
namespace splat::cli {
void registerCompare(CLI::App&) {}
}  // namespace splat::cli
