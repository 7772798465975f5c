#include "rigcal/calib/calibration_scheduler.hpp"

#include <cmath>

namespace rigcal::calib {

CalibrationBudget::CalibrationBudget(Clock::time_point start, double deadline_s, std::size_t runs,
                                     const registration::CancelToken* cancel)
    : end_(Clock::time_point::max()),
      remaining_runs_(runs == 0 ? 1 : runs),
      limited_(std::isfinite(deadline_s) && deadline_s > 0),
      cancel_(cancel) {
  if (limited_)
    end_ = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(deadline_s));
}

registration::Deadline CalibrationBudget::next() {
  if (!limited_) return registration::Deadline::never(cancel_);
  const auto now = Clock::now();
  const std::size_t share = remaining_runs_;
  if (remaining_runs_ > 1) --remaining_runs_;
  if (now >= end_) return registration::Deadline::at(end_, cancel_);
  return registration::Deadline::at(now + (end_ - now) / static_cast<long>(share), cancel_);
}

registration::Deadline CalibrationBudget::overall() const {
  return limited_ ? registration::Deadline::at(end_, cancel_) : registration::Deadline::never(cancel_);
}

double secondsLeft(const registration::Deadline& deadline) {
  if (deadline.when() == registration::Deadline::Clock::time_point::max()) return 1e18;
  return std::chrono::duration<double>(deadline.when() - registration::Deadline::Clock::now()).count();
}

bool fits(const registration::Deadline& deadline, double seconds) {
  return !deadline.expired() && secondsLeft(deadline) >= seconds;
}

}  // namespace rigcal::calib
