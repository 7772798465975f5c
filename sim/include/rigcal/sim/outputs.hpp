#pragma once
// The files `rigcal sim` writes besides the capture: the ground truth, the pose sensor's trajectory,
// a ready-to-use rig.yaml with perturbed initial extrinsics, and the sensor calibration/metadata files
// rig.yaml refers to. All are byte-identical for the same scenario and seed.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/sim/simulation.hpp"

namespace rigcal::sim {

/// Initial T_base_sensor per sensor: the truth perturbed by exactly the scenario's translation and
/// rotation magnitudes in seeded random directions. A calibration lidar's perturbation is applied to
/// its extrinsic relative to the mapping lidar (so T_mapping_calib is off by exactly that much); the
/// mapping lidar's own T_base_mapping is perturbed when perturbation.mapping_lidar is set.
std::map<std::string, Pose> perturbedExtrinsics(const Scenario& scenario);

/// truth.yaml: T_base_sensor, T_mapping_calib, clock offsets, scan phases, pose-sensor truth.
void writeTruthYaml(const Simulation& sim, const std::filesystem::path& file);

/// One sample of the pose sensor as poses.csv (and the bag's /odom) carry it.
struct PoseSample {
  TimeNs stamp_ns = 0;                     // pose sensor clock
  Pose T_world_pose = Pose::Identity();    // noise and origin included
};
/// The pose sensor (or base_link when the scenario has none) at its rate, noise drawn as for poses.csv.
std::vector<PoseSample> poseSamples(const Simulation& sim);
/// The pose sensor's name ("base_link" when the scenario has none).
std::string poseFrame(const Simulation& sim);

/// poses.csv: the pose sensor (or base_link when the scenario has none) at its rate, lidar_align
/// layout `timestamp_ns, index, px, py, pz, qw, qx, qy, qz`, with a `#` header; optional noise.
void writePosesCsv(const Simulation& sim, const std::filesystem::path& file);

/// rig.yaml in `dir` plus, beside it, each sensor's vendor file (Velodyne calibration YAML, Hesai
/// angle CSV, Ouster sensor_info JSON) with the angles the simulation used. Returns the files written.
std::vector<std::filesystem::path> writeRigFiles(const Simulation& sim, const std::filesystem::path& dir);

/// The vendor calibration/metadata file for one sensor ("" when the model needs none): its name and text.
std::pair<std::string, std::string> vendorFile(const SensorSpec& sensor, const LidarModel& model);

}  // namespace rigcal::sim
