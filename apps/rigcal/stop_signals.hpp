#pragma once
// SIGINT/SIGTERM as a flag: while a StopSignals guard lives, the first signal sets stopRequested()
// (an atomic store, async-signal-safe) instead of killing the process, so a job can finish cleanly.
#include <atomic>
#include <csignal>

namespace rigcal::app {

class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  /// The flag the handler sets; long waits poll it.
  static const std::atomic<bool>& flag();
  static bool requested() { return flag().load(std::memory_order_relaxed); }

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

}  // namespace rigcal::app
