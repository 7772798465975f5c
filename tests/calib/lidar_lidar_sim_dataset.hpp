#pragma once
// CalibrationDatasets built straight from the simulator (no pipeline): a short stretch of a preset is
// simulated; the mapping trajectory and the mapping clouds come from the truth (optionally with pose
// noise), keyframes every metre of path, calibration frames paired with the keyframes spread along the
// path, and each calibration lidar's initial extrinsic perturbed from the truth by a given amount.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/pipeline/calibration_dataset.hpp"

namespace rigcal::test {

struct SimDatasetOptions {
  std::string scenario = "parking-lot";
  double seconds = 10.0;         // simulated after dropping the preset's initial stop
  int frames = 4;                // calibration frames per calibration lidar, spread along the path
  double perturb_m = 0.3;        // initial-guess error of every calibration lidar
  double perturb_deg = 5.0;
  double pose_noise_m = 0.0;     // σ per axis added to each mapping pose
  double pose_noise_deg = 0.0;
  double mapping_leaf = 0.1;     // the mapper's leaf_size_input on the stored clouds
  /// Ground bumps (m; < 0 keeps the preset's). The car rests on its wheels, so on 4 cm bumps every 5 m
  /// its pitch wanders by degrees and no plane fit recovers the wheel-contact attitude to 0.05°.
  double bump_amplitude_m = -1.0;
  std::uint64_t seed = 7;
};

struct SimDatasets {
  config::Parameters params;  // tuned to the short stretch (dense window, frame spacing)
  std::vector<pipeline::CalibrationDataset> datasets;  // one per calibration lidar
  std::map<std::string, Pose> truth_T_mapping_calib;
  Pose truth_T_base_mapping = Pose::Identity();
  /// Mapping clouds (deskewed, mapping frame at their stamp) around the last keyframe, and that pose.
  std::vector<Eigen::Vector3d> ground_cloud_mapping;
};

/// Simulates and builds (a few seconds of CPU: call once per test suite).
SimDatasets buildSimDatasets(const SimDatasetOptions& options);

/// The lidar-lidar suites' common data: a flat stretch of the parking lot (no bumps; shorter, with fewer
/// frames, under the sanitizers), built on first use (a suite that skips never pays for it) and kept until
/// releaseFlatParkingLot() (a suite's TearDownTestSuite).
const SimDatasets& flatParkingLot();
void releaseFlatParkingLot();

/// `T` moved by `metres` and `degrees` in fixed pseudo-random directions drawn from `seed`.
Pose perturb(const Pose& T, double metres, double degrees, std::uint64_t seed);

}  // namespace rigcal::test
