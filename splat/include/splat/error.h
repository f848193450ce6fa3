#pragma once
// Errors raised by the splat library. Every failure is an exception carrying one
// actionable line (what, where, why); the command-line tool prints it and exits non-zero.
#include <stdexcept>
#include <string>

namespace splat {

class Error : public std::runtime_error {
  public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// A malformed option value, a combination that cannot run, or an option that does not fit
/// the input it is applied to (a time step past the last one the file holds): the command
/// line exits with its usage status (2), Python raises splat.InputError.
class OptionError : public Error {
  public:
    explicit OptionError(const std::string& message) : Error(message) {}
};

}  // namespace splat
