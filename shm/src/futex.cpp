#include "rigcal/shm/futex.hpp"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <ctime>

namespace rigcal::shm {

namespace {

std::uint32_t* address(std::atomic<std::uint32_t>& word) {
  // std::atomic<uint32_t> is a lock-free 32-bit object (static_assert in ring_layout.hpp): the kernel may
  // read it as the plain word it is.
  return reinterpret_cast<std::uint32_t*>(&word);
}

}  // namespace

FutexWait futexWait(std::atomic<std::uint32_t>& word, std::uint32_t expected,
                    std::chrono::nanoseconds timeout) {
  if (timeout.count() <= 0) return FutexWait::kTimedOut;
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(timeout.count() / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(timeout.count() % 1'000'000'000);
  // FUTEX_WAIT, not FUTEX_WAIT_PRIVATE: the word is shared between processes. The timeout is relative.
  const long rc = ::syscall(SYS_futex, address(word), FUTEX_WAIT, expected, &ts, nullptr, 0);
  if (rc == 0) return FutexWait::kWoken;
  switch (errno) {
    case EAGAIN: return FutexWait::kValueChanged;
    case ETIMEDOUT: return FutexWait::kTimedOut;
    case EINTR: return FutexWait::kInterrupted;
    default: return FutexWait::kWoken;  // EFAULT/EINVAL cannot happen for a mapped aligned word; re-check
  }
}

int futexWakeAll(std::atomic<std::uint32_t>& word) {
  const long rc = ::syscall(SYS_futex, address(word), FUTEX_WAKE, INT_MAX, nullptr, nullptr, 0);
  return rc < 0 ? 0 : static_cast<int>(rc);
}

}  // namespace rigcal::shm
