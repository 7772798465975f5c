#pragma once
// Byte-level helpers shared by the vendor encoders (little- and big-endian stores, quantisation).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "rigcal/core/time.hpp"
#include "rigcal/sim/firing.hpp"

namespace rigcal::sim::encoders {

inline void putU16le(std::uint8_t* p, std::uint32_t v) {
  p[0] = std::uint8_t(v);
  p[1] = std::uint8_t(v >> 8);
}
inline void putU32le(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = std::uint8_t(v >> (8 * i));
}
inline void putU64le(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = std::uint8_t(v >> (8 * i));
}

/// A return's range in counts of `unit_m` (0 = no return), saturated to `max_count`.
inline std::uint32_t rangeCounts(const LaserReturn& r, double inv_unit, std::uint32_t max_count) {
  if (!r.valid) return 0;
  const double c = std::round(double(r.range_m) * inv_unit);
  return c <= 0 ? 0 : std::uint32_t(std::min(c, double(max_count)));
}

/// Rotor azimuth in hundredths of a degree, [0, 36000).
inline std::uint32_t azimuthHundredths(double azimuth_deg) {
  long a = std::lround(azimuth_deg * 100.0) % 36000;
  if (a < 0) a += 36000;
  return std::uint32_t(a);
}

inline TimeNs floorDivNs(TimeNs a, TimeNs b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }
inline TimeNs floorModNs(TimeNs a, TimeNs b) { return a - floorDivNs(a, b) * b; }

}  // namespace rigcal::sim::encoders
