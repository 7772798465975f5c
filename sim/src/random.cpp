#include "rigcal/sim/random.hpp"

#include <algorithm>
#include <cmath>

namespace rigcal::sim {

double normalFromBits(std::uint64_t bits1, std::uint64_t bits2) {
  // 1 − u is in (0, 1]: log never sees zero.
  const double u1 = 1.0 - unitFromBits(bits1);
  const double u2 = unitFromBits(bits2);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

std::int64_t Rng::uniformInt(std::int64_t lo, std::int64_t hi) {
  if (hi <= lo) return lo;
  const std::uint64_t range = std::uint64_t(hi - lo) + 1;
  if (range == 0) return std::int64_t(engine_());  // the full 64-bit range
  const std::uint64_t limit = ~std::uint64_t(0) - (~std::uint64_t(0) % range);
  std::uint64_t v = engine_();
  while (v >= limit) v = engine_();
  return lo + std::int64_t(v % range);
}

double Rng::normal() {
  const std::uint64_t a = engine_();
  const std::uint64_t b = engine_();
  return normalFromBits(a, b);
}

Eigen::Vector3d Rng::unitVector() {
  const double z = uniform(-1.0, 1.0);
  const double phi = uniform(0.0, 2.0 * M_PI);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace rigcal::sim
