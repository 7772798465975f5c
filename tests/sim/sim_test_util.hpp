#pragma once
// Small scenarios for the simulator's tests: fast to simulate, deterministic, with knobs.
#include <yaml-cpp/yaml.h>

#include <string>

#include "rigcal/core/pose.hpp"
#include "rigcal/sim/scenario.hpp"

namespace rigcal::sim::test {

/// One lidar of `model` on the roof, moving at `speed_kmh` (with an optional turn) through the
/// parking-lot layout; noise as given.
inline Scenario movingLidar(const std::string& model, double speed_kmh, double turn_deg, double range_sigma,
                            double dropout, double duration_s = 2.0) {
  const std::string text = R"(
scenario: test-moving
seed: 11
rig:
  mapping_lidar: lidar
  sensors:
    - {name: lidar, model: )" + model + R"(, address: 192.168.1.201, port: 2368,
       extrinsic: {x: 1.0, y: 0.2, z: 1.9, roll_deg: 2.0, pitch_deg: -3.0, yaw_deg: 10.0}, scan_phase_deg: 33}
scene: {layout: parking-lot, size: [100, 80]}
trajectory:
  start: {x: -20, y: -6, yaw_deg: 0, speed_kmh: )" + std::to_string(speed_kmh) + R"(}
  segments:
    - {type: cruise, duration: )" + std::to_string(duration_s) + R"(, turn_deg: )" + std::to_string(turn_deg) + R"(}
noise: {range_sigma_m: )" + std::to_string(range_sigma) + R"(, dropout: )" + std::to_string(dropout) +
                           R"(, intensity_sigma: 0}
)";
  return parseScenario(text, "test scenario");
}

/// A pose written as {x, y, z, roll, pitch, yaw} (metres, radians), as truth.yaml holds it.
inline Pose poseFrom(const YAML::Node& n) {
  return fromXyzRpy({n["x"].as<double>(), n["y"].as<double>(), n["z"].as<double>(), n["roll"].as<double>(),
                     n["pitch"].as<double>(), n["yaw"].as<double>()});
}

}  // namespace rigcal::sim::test
