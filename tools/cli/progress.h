#pragma once
// Progress of long commands (rotate, popping, study): on a terminal, one line redrawn at
// most ten times a second with a bar, units done, rate and ETA; otherwise a plain line
// every 10% (or 10 seconds); nothing with --quiet. Ctrl-C (SIGINT) or SIGTERM asks the
// work to stop: the next progress call returns false, the library cancels cleanly, and
// only complete files are left.
#include <chrono>
#include <cstddef>
#include <string>

namespace splat::cli {

class ProgressReporter {
  public:
    /// `unit` names what is counted ("frames").
    ProgressReporter(std::string unit, bool quiet);
    /// Reports `done` of `total`; returns false once the user has interrupted.
    bool operator()(std::size_t done, std::size_t total, const std::string& what);
    /// Ends the progress line (terminal) before other output.
    void finish();

  private:
    std::string unit_;
    bool quiet_, tty_;
    std::chrono::steady_clock::time_point start_, lastDraw_;
    int lastDecile_ = -1;
    bool drawn_ = false;
};

/// Installs the SIGINT/SIGTERM handlers that set the interrupted flag.
void installInterruptHandler();
bool interrupted();

}  // namespace splat::cli
