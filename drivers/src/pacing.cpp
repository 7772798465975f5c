#include "rigcal/drivers/pacing.hpp"

#include <algorithm>
#include <cerrno>
#include <ctime>

namespace rigcal::drivers {

namespace {
constexpr TimeNs kStopCheckNs = 10 * kNsPerMs;
}

TimeNs monotonicNow() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return TimeNs(ts.tv_sec) * kNsPerSec + ts.tv_nsec;
}

bool sleepUntil(TimeNs deadline, const std::atomic<bool>& stop) {
  while (!stop.load(std::memory_order_relaxed)) {
    const TimeNs now = monotonicNow();
    if (now >= deadline) return true;
    const TimeNs wake = std::min(deadline, now + kStopCheckNs);
    timespec ts{};
    ts.tv_sec = time_t(wake / kNsPerSec);
    ts.tv_nsec = long(wake % kNsPerSec);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      if (stop.load(std::memory_order_relaxed)) return false;
    }
  }
  return false;
}

}  // namespace rigcal::drivers
