#pragma once
// Bounded time for the calibration stage: one calibration_deadline_s for the whole run, shared fairly by
// the calibration lidars. Each lidar, when its turn comes, gets an equal share of what is left, so time
// an early lidar did not need goes to the later ones and the last one ends at the overall deadline.
// Inside a lidar's share, work that cannot finish in time is not started (see fits()).
#include <chrono>
#include <cstddef>

#include "rigcal/registration/deadline.hpp"

namespace rigcal::calib {

class CalibrationBudget {
 public:
  using Clock = registration::Deadline::Clock;

  /// `runs` calibration lidars share `deadline_s` seconds from `start`. deadline_s ≤ 0 or infinite: no limit.
  CalibrationBudget(Clock::time_point start, double deadline_s, std::size_t runs,
                    const registration::CancelToken* cancel = nullptr);

  /// The deadline of the next lidar's run (call once per lidar, in order).
  registration::Deadline next();
  /// The overall deadline.
  [[nodiscard]] registration::Deadline overall() const;
  [[nodiscard]] bool limited() const { return limited_; }

 private:
  Clock::time_point end_;
  std::size_t remaining_runs_;
  bool limited_;
  const registration::CancelToken* cancel_;
};

/// True when work predicted to take `seconds` can finish before `deadline` (always, without one).
bool fits(const registration::Deadline& deadline, double seconds);

/// Seconds left before `deadline` (a large number without one).
double secondsLeft(const registration::Deadline& deadline);

}  // namespace rigcal::calib
