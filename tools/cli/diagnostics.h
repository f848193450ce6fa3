#pragma once
// What the command line tells its user besides its results (README "Command line", exit
// statuses): warnings are one line `splat: warning: ...` on stderr; errors one line
// `splat: error: ...`. A UsageError (unknown option, malformed value, bad combination, bad
// scene file) exits with status 2, any other failure of the work with status 1.
#include <string>

#include "splat/error.h"

namespace splat::cli {

inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

class UsageError : public Error {
  public:
    explicit UsageError(const std::string& message) : Error(message) {}
};

/// Prints `splat: warning: LINE` on stderr, one line per line of `text`.
void warn(const std::string& text);

/// Runs `parse` (reading options, no work); a splat::Error it throws becomes a UsageError.
template <class F>
auto asUsage(F&& parse) -> decltype(parse()) {
    try {
        return parse();
    } catch (const UsageError&) {
        throw;
    } catch (const Error& e) {
        throw UsageError(e.what());
    }
}

}  // namespace splat::cli
