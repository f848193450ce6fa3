#pragma once
// Progress and cancellation inside one frame (RenderSettings::progress): the parallel loops of
// the splatters (per tile or chunk) and of the reference ray caster (per row) tick it; once
// the callback returns false, the loops skip what has not started and finish() throws
// splat::Cancelled.
#include <atomic>
#include <cstddef>
#include <mutex>
#include <string>

#include "splat/settings.h"

namespace splat {

class FrameProgress {
  public:
    FrameProgress(const ProgressFn& fn, std::size_t total, std::string what)
        : fn_(fn), total_(total), what_(std::move(what)) {}

    bool stopped() const { return stop_.load(std::memory_order_relaxed); }
    /// One more unit done; calls the callback (serialised: done counts up to total in order).
    void tick() {
        if (!fn_) return;
        const std::lock_guard<std::mutex> lock(mutex_);
        if (stop_) return;
        if (!fn_(++done_, total_, what_)) stop_ = true;
    }
    /// Throws splat::Cancelled when the callback asked to stop.
    void finish() const {
        if (stopped()) throw Cancelled();
    }

  private:
    const ProgressFn& fn_;
    std::size_t total_, done_ = 0;
    std::string what_;
    std::mutex mutex_;
    std::atomic<bool> stop_{false};
};

}  // namespace splat
