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

/// An option that does not fit the input it is applied to (a time step past the last one
/// the file holds): the command line reports it as a usage error (exit status 2).
class OptionError : public Error {
  public:
    explicit OptionError(const std::string& message) : Error(message) {}
};

}  // namespace splat
