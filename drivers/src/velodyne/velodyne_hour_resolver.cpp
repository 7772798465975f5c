// µs past the top of the hour → absolute time, the hour taken from a reference clock (velodyne_decoder.hpp).
#include <algorithm>
#include <cstdlib>

#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"

namespace rigcal::drivers::velodyne {
namespace {

constexpr TimeNs kNsPerHour = 3600 * kNsPerSec;

TimeNs floorDiv(TimeNs a, TimeNs b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

TimeNs HourResolver::resolve(std::uint32_t micros_past_hour, TimeNs reference_ns) {
  constexpr TimeNs kLimit = TimeNs(1) << 62;
  reference_ns = std::clamp(reference_ns, -kLimit, kLimit);
  const TimeNs in_hour = TimeNs(micros_past_hour) * kNsPerUs;
  constexpr TimeNs kHalfHour = kNsPerHour / 2;
  if (!anchored_ || std::abs(reference_ns - last_reference_ns_) > 10 * 60 * kNsPerSec) {
    const TimeNs hour = floorDiv(reference_ns, kNsPerHour) * kNsPerHour;
    TimeNs best = hour;
    for (TimeNs candidate : {hour - kNsPerHour, hour + kNsPerHour})
      if (std::abs(candidate + in_hour - reference_ns) < std::abs(best + in_hour - reference_ns))
        best = candidate;
    hour_start_ns_ = best;
    anchored_ = true;
  } else {
    const TimeNs t = hour_start_ns_ + in_hour;
    if (t < last_ns_ - kHalfHour) hour_start_ns_ += kNsPerHour;       // wrapped past the top of the hour
    else if (t > last_ns_ + kHalfHour) hour_start_ns_ -= kNsPerHour;  // a late packet from the last hour
  }
  last_ns_ = hour_start_ns_ + in_hour;
  last_reference_ns_ = reference_ns;
  return last_ns_;
}

}  // namespace rigcal::drivers::velodyne
