#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"

#include <algorithm>
#include <cmath>

namespace rigcal::calib {
namespace {

CalibrationBudget::Clock::duration toDuration(double seconds) {
  return std::chrono::duration_cast<CalibrationBudget::Clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace

CalibrationBudget::CalibrationBudget(double deadline_s, std::size_t runs, const registration::CancelToken* cancel)
    : total_s_(deadline_s),
      limited_(std::isfinite(deadline_s) && deadline_s > 0),
      remaining_runs_(std::max<std::size_t>(runs, 1)),
      cancel_(cancel) {}

CalibrationBudget::CalibrationBudget(Clock::time_point start, double deadline_s, std::size_t runs,
                                     const registration::CancelToken* cancel)
    : CalibrationBudget(deadline_s, runs, cancel) {
  started_ = true;
  if (limited_) end_ = start + toDuration(deadline_s);
}

registration::Deadline CalibrationBudget::next() {
  const auto now = Clock::now();
  if (!started_) {
    started_ = true;
    if (limited_) end_ = now + toDuration(total_s_);
  } else if (paused_ && limited_) {
    end_ += now - paused_at_;  // the wait for this lidar's dataset was not calibration time
  }
  paused_ = false;
  if (!limited_) return registration::Deadline::never(cancel_);
  const std::size_t share = remaining_runs_;
  others_to_come_ = share > 1;
  if (remaining_runs_ > 1) --remaining_runs_;
  if (now >= end_) return registration::Deadline::at(end_, cancel_);
  return registration::Deadline::at(now + (end_ - now) / static_cast<long>(share), cancel_);
}

void CalibrationBudget::pause() {
  if (!started_ || paused_) return;
  paused_ = true;
  paused_at_ = Clock::now();
}

void CalibrationBudget::expectRuns(std::size_t runs) { remaining_runs_ = std::max<std::size_t>(runs, 1); }

registration::Deadline CalibrationBudget::overall() const {
  if (!limited_) return registration::Deadline::never(cancel_);
  if (!started_) return registration::Deadline::at(Clock::now() + toDuration(total_s_), cancel_);
  return registration::Deadline::at(paused_ ? end_ + (Clock::now() - paused_at_) : end_, cancel_);
}

double CalibrationBudget::spentSeconds() const {
  if (!started_ || !limited_) return 0.0;
  const auto now = paused_ ? paused_at_ : Clock::now();
  return total_s_ - std::chrono::duration<double>(end_ - now).count();
}

double secondsLeft(const registration::Deadline& deadline) {
  if (deadline.when() == registration::Deadline::Clock::time_point::max()) return 1e18;
  return std::chrono::duration<double>(deadline.when() - registration::Deadline::Clock::now()).count();
}

registration::Deadline earlierBy(const registration::Deadline& deadline, double seconds) {
  if (deadline.when() == registration::Deadline::Clock::time_point::max()) return deadline;
  const auto reserve = std::chrono::duration_cast<registration::Deadline::Clock::duration>(
      std::chrono::duration<double>(seconds));
  return registration::Deadline::at(deadline.when() - reserve, deadline.token());
}

bool fits(const registration::Deadline& deadline, double seconds) {
  return !deadline.expired() && secondsLeft(deadline) >= seconds;
}

}  // namespace rigcal::calib
