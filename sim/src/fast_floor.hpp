#pragma once
// Private: floor() for the scene's cell lookups, on their hot path.

namespace rigcal::sim::detail {

/// floor(v) for values well inside int range; std::floor is a libm call without SSE4.1.
inline int fastFloor(double v) {
  const int i = int(v);
  return i - (v < double(i));
}

}  // namespace rigcal::sim::detail
