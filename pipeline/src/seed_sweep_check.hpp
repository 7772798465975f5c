#pragma once
// A capture (or a driver started mid-rotation) begins with part of a sweep. Seeding the map with it
// leaves the next full sweeps half outside the map: they fail the fitness check and are lost until the
// map restarts. So the first seed must cover kCompleteSweep of the rotation: of the whole circle for the
// very first sweep, of the fullest sweep seen so far after that (a sensor with a limited field of view
// loses one sweep, never more). Private to the pipeline library.
#include <optional>
#include <string>

#include "rigcal/core/scan.hpp"

namespace rigcal::pipeline {

class SeedSweepCheck {
 public:
  static constexpr double kCompleteSweep = 0.9;

  /// Fraction of the 360 one-degree azimuth sectors around the sensor that hold a point.
  static double azimuthCoverage(const Scan& scan);

  /// Why `scan` cannot seed the map, or nothing when it can. Call only for scans that would seed it.
  std::optional<std::string> reject(const Scan& scan);

 private:
  bool checked_ = false;
  double best_coverage_ = 0.0;
};

}  // namespace rigcal::pipeline
