#pragma once
// Locale-independent, platform-independent number formatting for the generated files (byte-identical
// output for the same seed is a requirement).
#include <string>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/text_format.hpp"

namespace rigcal::sim::detail {

using rigcal::exact;
using rigcal::fixed;

/// "{x: …, y: …, z: …, roll: …, pitch: …, yaw: …}" (metres, radians).
inline std::string xyzRpyFlow(const Pose& T, int decimals = 9) {
  const XyzRpy v = toXyzRpy(T);
  return "{x: " + fixed(v.x, decimals) + ", y: " + fixed(v.y, decimals) + ", z: " + fixed(v.z, decimals) +
         ", roll: " + fixed(v.roll, decimals) + ", pitch: " + fixed(v.pitch, decimals) +
         ", yaw: " + fixed(v.yaw, decimals) + "}";
}

}  // namespace rigcal::sim::detail
