#pragma once
// What the command line tells its user besides its results (docs/command-line.md, exit
// statuses): warnings are one line `splat: warning: ...` on stderr; errors one line
// `splat: error: ...`. A UsageError (unknown option, malformed value, bad combination, bad
// scene file) exits with status 2, any other failure of the work with status 1.
#include <string>

#include "splat/error.h"
#include "splat/options.h"

namespace splat::cli {

inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

/// A usage error of the command line; the library's OptionError (a malformed option value)
/// is one too.
class UsageError : public OptionError {
  public:
    explicit UsageError(const std::string& message) : OptionError(message) {}
};

/// Prints `splat: warning: LINE` on stderr, one line per line of `text`.
void warn(const std::string& text);

/// Runs `parse` (reading options, no work); a splat::Error it throws becomes a UsageError.
template <class F>
auto asUsage(F&& parse) -> decltype(parse()) {
    try {
        return parse();
    } catch (const OptionError&) {
        throw;
    } catch (const Error& e) {
        throw UsageError(e.what());
    }
}

/// Runs `read` (reading options, maybe files); an OptionError it throws becomes a UsageError,
/// other errors (a file that cannot be read) stay failures of the work.
template <class F>
auto asOptionUsage(F&& read) -> decltype(read()) {
    try {
        return read();
    } catch (const UsageError&) {
        throw;
    } catch (const OptionError& e) {
        throw UsageError(e.what());
    }
}

}  // namespace splat::cli
