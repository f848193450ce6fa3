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

}  // namespace splat
