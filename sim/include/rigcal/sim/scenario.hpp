#pragma once
// A scenario file (YAML) says everything a simulated recording needs: the rig (sensors, models,
// extrinsics, addresses, scan phases and clock offsets), the optional pose sensor, the scene, the
// drive, the noise, and how far rig.yaml's initial extrinsics are perturbed from the truth.
// Presets live in sim/scenarios/ and are compiled in; see sim/scenarios/README.md for the format.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/time.hpp"
#include "rigcal/sim/scene_generator.hpp"
#include "rigcal/sim/trajectory.hpp"

namespace rigcal::sim {

/// A malformed scenario: "<file>:<line>:<column>: <what>".
struct ScenarioError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Outage {
  double from_s = 0, to_s = 0;  // seconds after the start: the sensor sends nothing
};

struct SensorSpec {
  std::string name;
  std::string model;           // a LidarModel name
  Pose T_base_sensor = Pose::Identity();
  std::string address;         // the sensor's IPv4 address
  std::uint16_t port = 2368;   // destination UDP port
  double scan_phase_deg = 0;   // rotor azimuth at every whole second of sensor time
  TimeNs clock_offset_ns = 0;  // sensor clock = true clock + offset
  bool time_source_sensor = true;  // rig.yaml time_source: sensor (true) or host
  std::vector<Outage> outages;
  bool ouster_legacy = false;  // Ouster: LEGACY packets instead of RNG19_RFL8_SIG16_NIR16
};

struct PoseSensorSpec {
  std::string name = "pose";
  Pose T_base_pose = Pose::Identity();
  double rate_hz = 100.0;
  double position_noise_m = 0.0;     // σ per axis
  double rotation_noise_deg = 0.0;   // σ of a random rotation vector's components
  TimeNs clock_offset_ns = 0;        // pose stamps = true time + offset
  Eigen::Vector3d origin{0, 0, 0};   // added to positions (e.g. UTM-like coordinates)
};

struct NoiseSpec {
  double range_sigma_m = 0.02;
  double dropout = 0.003;        // base probability that any return is lost
  double intensity_sigma = 3.0;  // on the 0..255 scale
};

struct PerturbationSpec {
  double translation_m = 0.3;    // |Δt| of every perturbed extrinsic
  double rotation_deg = 5.0;     // rotation angle of every perturbed extrinsic
  bool mapping_lidar = true;     // also perturb T_base_mapping (base-lidar calibration input)
};

struct Scenario {
  std::string name;
  std::string description;
  std::filesystem::path file;    // empty for a compiled-in preset
  std::uint64_t seed = 1;
  TimeNs start_time_ns = 1'700'000'000'000'000'000;  // true time at the trajectory's start
  std::string rig_name;
  std::string base_frame = "base_link";
  std::string mapping_lidar;
  std::vector<std::string> calibration_lidars;
  std::vector<SensorSpec> sensors;
  std::optional<PoseSensorSpec> pose_sensor;
  SceneSpec scene;
  TrajectorySpec trajectory;
  NoiseSpec noise;
  PerturbationSpec perturbation;
  /// Calibration parameters copied verbatim into rig.yaml (name, YAML scalar text).
  std::vector<std::pair<std::string, std::string>> rig_parameters;

  [[nodiscard]] std::size_t sensorIndex(const std::string& name) const;
};

/// The compiled-in presets: parking-lot, street, lost, pose.
std::vector<std::string> builtinScenarioNames();

/// A preset by name, or a scenario file by path (anything containing '/' or ending in .yaml).
/// Throws ScenarioError.
Scenario loadScenario(const std::string& name_or_file);
/// Parses scenario YAML text; `origin` names it in error messages.
Scenario parseScenario(const std::string& text, const std::string& origin);

}  // namespace rigcal::sim
