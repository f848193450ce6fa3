// TEMPORARY placeholder while the renderer is written.
#include "commands.h"
namespace splat::cli {
void registerRender(CLI::App&) {}
}  // namespace splat::cli
