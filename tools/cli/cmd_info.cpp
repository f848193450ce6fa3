// TEMPORARY placeholder while the loaders are written.
#include "commands.h"
namespace splat::cli {
void registerInfo(CLI::App&) {}
}  // namespace splat::cli
