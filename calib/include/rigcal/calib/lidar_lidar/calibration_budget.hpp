#pragma once
// Bounded time for the calibration stage: one calibration_deadline_s for the whole calibration, shared
// fairly by the calibration lidars. Each lidar, when its turn comes, gets an equal share of what is left
// among the lidars still to come, so time an early lidar did not need goes to the later ones and the
// last one ends at the overall deadline. Inside a lidar's share, work that cannot finish in time is not
// started (see fits()).
//
// What the deadline measures: calibration time. The clock starts when the first lidar's calibration
// starts and is paused while no calibration runs (pause(): the worker waits for the next lidar's
// dataset, whose frame budget fills later in the drive). A lidar that arrives a minute later still gets
// its fair share, and the lidar-lidar stage as a whole never spends more than the deadline.
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
  /// The same, with the clock started by the first next().
  CalibrationBudget(double deadline_s, std::size_t runs, const registration::CancelToken* cancel = nullptr);

  /// The deadline of the next lidar's run, starting now (call once per lidar, in order). Resumes a paused clock.
  registration::Deadline next();
  /// No calibration runs until the next next(): that time does not count.
  void pause();
  /// Only `runs` more lidars will come (end of input: the others got no dataset); they share what is left.
  void expectRuns(std::size_t runs);

  /// The last next() left time for lidars still to come (its share was not all that is left).
  [[nodiscard]] bool othersToCome() const { return others_to_come_; }

  /// The overall deadline (as of now: a pause moves it later).
  [[nodiscard]] registration::Deadline overall() const;
  [[nodiscard]] bool limited() const { return limited_; }
  [[nodiscard]] double totalSeconds() const { return total_s_; }
  /// Calibration seconds spent so far (pauses excluded); 0 before the first next().
  [[nodiscard]] double spentSeconds() const;

 private:
  double total_s_;
  bool limited_;
  bool started_ = false;
  bool paused_ = false;
  Clock::time_point end_ = Clock::time_point::max();
  Clock::time_point paused_at_{};
  std::size_t remaining_runs_;
  bool others_to_come_ = false;
  const registration::CancelToken* cancel_;
};

/// True when work predicted to take `seconds` can finish before `deadline` (always, without one).
bool fits(const registration::Deadline& deadline, double seconds);

/// Seconds left before `deadline` (a large number without one).
double secondsLeft(const registration::Deadline& deadline);

/// The same deadline `seconds` earlier (same cancel token), leaving that much for work after it; no limit stays
/// no limit.
registration::Deadline earlierBy(const registration::Deadline& deadline, double seconds);

}  // namespace rigcal::calib
