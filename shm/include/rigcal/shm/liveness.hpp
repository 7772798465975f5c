#pragma once
// Is a process still the one we think it is? A pid alone is not enough (pids are recycled), so a process is
// identified by its pid and its start time (field 22 of /proc/<pid>/stat, clock ticks since boot).
#include <chrono>
#include <cstdint>
#include <optional>

#include "rigcal/shm/ring_layout.hpp"
#include "rigcal/shm/ring_stats.hpp"

namespace rigcal::shm {

struct ProcessIdentity {
  std::int32_t pid = 0;
  std::uint64_t start_time = 0;
};

/// The start time of `pid`; nullopt when no such process exists or it is a zombie (killed, not reaped).
std::optional<std::uint64_t> processStartTime(std::int32_t pid);

/// This process.
ProcessIdentity selfIdentity();

/// True while `who.pid` runs and is still the process that started at `who.start_time`.
bool processAlive(const ProcessIdentity& who);

/// CLOCK_MONOTONIC and CLOCK_REALTIME in nanoseconds (the monotonic clock is system-wide, so stamps taken
/// by one process compare with another's).
std::int64_t monotonicNs();
std::int64_t realtimeNs();

/// The writer's status from a mapped header: state word, then pid + start time, then heartbeat age.
WriterStatus evaluateWriter(const RingHeader& header, std::chrono::nanoseconds stall_after);

}  // namespace rigcal::shm
