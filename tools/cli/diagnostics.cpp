// Warning lines (see diagnostics.h).
#include "diagnostics.h"

#include <cstdio>
#include <sstream>

#include "parallel.h"

namespace splat::cli {

void warn(const std::string& text) {
    if (workerProcess()) return;  // rank 0 says it once (parallel.h)
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) std::fprintf(stderr, "splat: warning: %s\n", line.c_str());
}

}  // namespace splat::cli
