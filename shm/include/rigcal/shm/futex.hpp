#pragma once
// FUTEX_WAIT / FUTEX_WAKE on a 32-bit word in shared memory. The non-private operations are used: the
// kernel keys the futex by the mapped page, so processes that map the segment at different addresses meet
// on the same word. Waits always carry a timeout so the caller can run its liveness checks.
#include <atomic>
#include <chrono>
#include <cstdint>

namespace rigcal::shm {

enum class FutexWait {
  kWoken,         // FUTEX_WAKE (or a spurious wake-up: re-check the condition)
  kValueChanged,  // the word no longer held `expected` when the kernel looked
  kTimedOut,
  kInterrupted,   // a signal arrived
};

/// Sleeps while `word` holds `expected`, for at most `timeout` (≤ 0: returns kTimedOut at once).
FutexWait futexWait(std::atomic<std::uint32_t>& word, std::uint32_t expected,
                    std::chrono::nanoseconds timeout);

/// Wakes every process and thread sleeping on `word`; returns how many woke.
int futexWakeAll(std::atomic<std::uint32_t>& word);

}  // namespace rigcal::shm
