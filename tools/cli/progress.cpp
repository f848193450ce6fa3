// Progress reporting and interruption for long commands (see progress.h).
#include "progress.h"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>

namespace splat::cli {

namespace {
std::atomic<bool> gInterrupted{false};
extern "C" void onSignal(int) { gInterrupted = true; }

std::string clock(double seconds) {
    const long s = long(seconds + 0.5);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
    return buf;
}
}  // namespace

void installInterruptHandler() {
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
}

bool interrupted() { return gInterrupted; }

ProgressReporter::ProgressReporter(std::string unit, bool quiet)
    : unit_(std::move(unit)),
      quiet_(quiet),
      tty_(::isatty(::fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()),
      lastDraw_(start_) {}

bool ProgressReporter::operator()(std::size_t done, std::size_t total, const std::string& what) {
    if (gInterrupted) return false;
    if (quiet_ || total == 0) return true;
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0 ? double(done) / elapsed : 0;
    const double eta = rate > 0 ? double(total - done) / rate : 0;
    if (tty_) {
        if (done < total && now - lastDraw_ < std::chrono::milliseconds(100)) return true;
        lastDraw_ = now;
        const int width = 24, filled = int(double(width) * double(done) / double(total));
        std::string bar(std::size_t(filled), '#');
        bar.resize(std::size_t(width), '.');
        std::fprintf(stderr, "\r[%s] %zu/%zu %s  %.1f %s/s  ETA %s  %-28.28s", bar.c_str(), done,
                     total, unit_.c_str(), rate, unit_.c_str(), clock(eta).c_str(), what.c_str());
        drawn_ = true;
    } else {
        const int decile = int(10.0 * double(done) / double(total));
        if (decile == lastDecile_ && now - lastDraw_ < std::chrono::seconds(10)) return true;
        lastDecile_ = decile;
        lastDraw_ = now;
        std::fprintf(stderr, "splat: %zu/%zu %s (%.0f%%), %.1f %s/s, ETA %s\n", done, total,
                     unit_.c_str(), 100.0 * double(done) / double(total), rate, unit_.c_str(),
                     clock(eta).c_str());
    }
    std::fflush(stderr);
    return true;
}

void ProgressReporter::finish() {
    if (drawn_) std::fprintf(stderr, "\n");
    drawn_ = false;
}

}  // namespace splat::cli
