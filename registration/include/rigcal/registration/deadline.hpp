#pragma once
// When a registration must stop: a steady-clock deadline and/or a cancel token another thread sets.
// Registrations poll it between chunks of work (a few hundred points), so they stop within about a
// chunk's time of it and return the best result fully evaluated so far.
#include <atomic>
#include <chrono>

namespace rigcal::registration {

/// Set by any thread to ask running registrations to stop early. Not copyable (it is shared by address).
class CancelToken {
 public:
  CancelToken() = default;
  CancelToken(const CancelToken&) = delete;
  CancelToken& operator=(const CancelToken&) = delete;

  void cancel() noexcept { flag_.store(true, std::memory_order_relaxed); }
  void reset() noexcept { flag_.store(false, std::memory_order_relaxed); }
  [[nodiscard]] bool cancelled() const noexcept { return flag_.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> flag_{false};
};

enum class StopReason { kNone, kTimeout, kCancelled };

class Deadline {
 public:
  using Clock = std::chrono::steady_clock;

  /// Never expires (unless a token is attached and cancelled).
  Deadline() = default;
  static Deadline never(const CancelToken* token = nullptr) { return Deadline(Clock::time_point::max(), token); }
  static Deadline at(Clock::time_point when, const CancelToken* token = nullptr) { return Deadline(when, token); }
  static Deadline after(Clock::duration budget, const CancelToken* token = nullptr) {
    return Deadline(Clock::now() + budget, token);
  }

  /// Cancellation wins over a timeout that happened at the same check.
  [[nodiscard]] StopReason check() const {
    if (token_ != nullptr && token_->cancelled()) return StopReason::kCancelled;
    if (when_ != Clock::time_point::max() && Clock::now() >= when_) return StopReason::kTimeout;
    return StopReason::kNone;
  }
  [[nodiscard]] bool expired() const { return check() != StopReason::kNone; }
  [[nodiscard]] Clock::time_point when() const { return when_; }
  [[nodiscard]] const CancelToken* token() const { return token_; }

 private:
  Deadline(Clock::time_point when, const CancelToken* token) : when_(when), token_(token) {}
  Clock::time_point when_ = Clock::time_point::max();
  const CancelToken* token_ = nullptr;
};

}  // namespace rigcal::registration
