#pragma once
// Replaying recorded time on the monotonic clock: absolute deadlines (no drift from summed sleeps).
#include <atomic>

#include "rigcal/core/time.hpp"

namespace rigcal::drivers {

TimeNs monotonicNow();

/// Sleeps until the monotonic time `deadline`, waking every 10 ms to check `stop`. False if stopped.
bool sleepUntil(TimeNs deadline, const std::atomic<bool>& stop);

}  // namespace rigcal::drivers
