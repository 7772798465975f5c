#pragma once
// Time in rigcal is a signed 64-bit count of nanoseconds (since the UNIX epoch for absolute stamps).
#include <cstdint>

namespace rigcal {

using TimeNs = std::int64_t;

inline constexpr TimeNs kNsPerUs = 1'000;
inline constexpr TimeNs kNsPerMs = 1'000'000;
inline constexpr TimeNs kNsPerSec = 1'000'000'000;

constexpr double toSeconds(TimeNs t) { return static_cast<double>(t) * 1e-9; }
constexpr TimeNs fromSeconds(double s) {
  return static_cast<TimeNs>(s * 1e9 + (s >= 0 ? 0.5 : -0.5));
}

/// Where a sensor's timestamps come from: its own clock (PTP/GPS, decoded from packets) or the host.
enum class TimeSource { kSensorClock, kHostReceive };

}  // namespace rigcal
