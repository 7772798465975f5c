#pragma once
// Locale-independent, platform-independent number formatting for the generated files (byte-identical
// output for the same seed is a requirement).
#include <charconv>
#include <string>

#include "rigcal/core/pose.hpp"

namespace rigcal::sim::detail {

/// Fixed-point with `decimals` digits; "-0.000" is written as "0.000".
inline std::string fixed(double v, int decimals) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals);
  std::string s(buf, r.ptr);
  if (s.front() == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

/// Shortest text that reads back to exactly v.
inline std::string exact(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

/// "{x: …, y: …, z: …, roll: …, pitch: …, yaw: …}" (metres, radians).
inline std::string xyzRpyFlow(const Pose& T, int decimals = 9) {
  const XyzRpy v = toXyzRpy(T);
  return "{x: " + fixed(v.x, decimals) + ", y: " + fixed(v.y, decimals) + ", z: " + fixed(v.z, decimals) +
         ", roll: " + fixed(v.roll, decimals) + ", pitch: " + fixed(v.pitch, decimals) +
         ", yaw: " + fixed(v.yaw, decimals) + "}";
}

}  // namespace rigcal::sim::detail
