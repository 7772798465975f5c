#include "seed_sweep_check.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace rigcal::pipeline {

double SeedSweepCheck::azimuthCoverage(const Scan& scan) {
  std::array<bool, 360> hit{};
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const double deg = std::atan2(double(scan.y[i]), double(scan.x[i])) * 180.0 / M_PI + 180.0;
    hit[std::min<std::size_t>(359, std::size_t(deg))] = true;
  }
  return double(std::count(hit.begin(), hit.end(), true)) / 360.0;
}

std::optional<std::string> SeedSweepCheck::reject(const Scan& scan) {
  const double coverage = azimuthCoverage(scan);
  const double required = kCompleteSweep * (checked_ ? best_coverage_ : 1.0);
  best_coverage_ = std::max(best_coverage_, coverage);
  const bool first_look = !checked_;
  checked_ = true;
  if (coverage >= required) return std::nullopt;
  std::ostringstream why;
  why << "incomplete sweep cannot seed the map: it covers " << std::lround(100 * coverage) << "% of the rotation"
      << (first_look ? "" : " (the fullest so far " + std::to_string(std::lround(100 * best_coverage_)) + "%)");
  return why.str();
}

}  // namespace rigcal::pipeline
