// TEMPORARY placeholder while the renderer is written.
#include "commands.h"
namespace splat::cli {
void registerRotate(CLI::App&) {}
}  // namespace splat::cli
