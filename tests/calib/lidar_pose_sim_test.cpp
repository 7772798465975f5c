// Lidar-pose calibration on the simulator's `pose` scenario: the physics (scene, ray casting with the
// VLP-16's firing timing, vehicle motion with roll/pitch excitation, range noise, a 15 ms clock offset)
// gives the scans, the simulator's poses.csv (noisy, UTM-like origin) the trajectory, truth.yaml's
// definitions the answer.
#include <gtest/gtest.h>

#include <cstring>
#include <iostream>

#include "rigcal/calib/lidar_pose/lidar_pose_calibration.hpp"
#include "rigcal/calib/lidar_pose/pose_csv.hpp"
#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/scenario.hpp"
#include "rigcal/sim/simulation.hpp"
#include "sanitizers.hpp"
#include "test_data.hpp"

namespace rigcal::calib {
namespace {

using test::kSanitized;

// Collects the decoded-equivalent sweeps of one sensor (sensor frame, sensor clock).
class ScanCollector : public sim::SimulationSink {
 public:
  void onScan(sim::SimulatedScan&& s) override { scans.push_back(std::move(s.scan)); }
  std::vector<Scan> scans;
};

struct SimRun {
  std::vector<Scan> scans;
  PoseCsv poses;
  Pose T_pose_lidar;     // truth
  double time_offset_s;  // truth: add to lidar time to get pose time
};

SimRun simulatePose(std::uint64_t seed, double duration_s) {
  sim::Scenario scenario = sim::loadScenario("pose");
  scenario.seed = seed;
  const sim::Simulation simulation(scenario);
  ScanCollector collector;
  sim::SimulationOptions options;
  options.max_duration_ns = fromSeconds(duration_s);
  simulation.run(collector, options);
  const test::TempDir dir;
  sim::writePosesCsv(simulation, dir / "poses.csv");
  SimRun run;
  run.scans = std::move(collector.scans);
  run.poses = readPoseCsv(dir / "poses.csv");
  const auto& pose_sensor = *scenario.pose_sensor;
  const auto& lidar = scenario.sensors.at(0);
  run.T_pose_lidar = pose_sensor.T_base_pose.inverse() * lidar.T_base_sensor;
  run.time_offset_s = toSeconds(pose_sensor.clock_offset_ns - lidar.clock_offset_ns);
  return run;
}

struct Errors {
  double translation_m, rotation_deg, time_ms;
  Eigen::Vector3d per_axis_cm;
};

Errors errorsOf(const LidarPoseResult& r, const SimRun& run) {
  const Eigen::Vector3d d = r.T_pose_lidar.translation() - run.T_pose_lidar.translation();
  return {d.norm(), rad2deg(rotationAngleBetween(r.T_pose_lidar, run.T_pose_lidar)),
          1e3 * std::abs(r.time_offset_s - run.time_offset_s), 100.0 * d};
}

bool bitIdentical(const LidarPoseResult& a, const LidarPoseResult& b) {
  return std::memcmp(a.T_pose_lidar.matrix().data(), b.T_pose_lidar.matrix().data(), 16 * sizeof(double)) == 0 &&
         std::memcmp(&a.time_offset_s, &b.time_offset_s, sizeof(double)) == 0 &&
         std::memcmp(&a.final_cost, &b.final_cost, sizeof(double)) == 0 &&
         a.local_evaluations == b.local_evaluations && a.global_evaluations == b.global_evaluations;
}

// Sanitizer builds check memory and threads on a short piece of the drive with fewer points and
// evaluations, not accuracy.
double drive_s() { return kSanitized ? 5.0 : 1e9; }

LidarPoseSettings testSettings() {
  LidarPoseSettings s;  // the defaults `rigcal calibrate-pose` uses
  if (kSanitized) {
    s.selection.keep_points_ratio = 0.004;
    s.max_evals = 30;
  }
  return s;
}

class LidarPoseOnSimulatedPoseScenario : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(LidarPoseOnSimulatedPoseScenario, RecoversExtrinsicAndTimeOffsetWithin2cm01deg1ms) {
  if (kSanitized && GetParam() != 4u) GTEST_SKIP() << "one seed is enough under sanitizers";
  const SimRun run = simulatePose(GetParam(), drive_s());
  ASSERT_GT(run.scans.size(), kSanitized ? 40u : 250u);
  const PoseTrajectory trajectory(run.poses);
  const LidarPoseSettings settings = testSettings();
  const LidarPoseResult r = calibrateLidarPose(run.scans, trajectory, settings);
  const Errors e = errorsOf(r, run);
  std::cout << "seed " << GetParam() << ": error " << 100 * e.translation_m << " cm (" << e.per_axis_cm.transpose()
            << "), " << e.rotation_deg << " deg, " << e.time_ms << " ms; " << r.points.size() << " points, "
            << r.global_evaluations << " + " << r.local_evaluations << " evaluations, " << r.total_seconds
            << " s\n"
            << r.observability.text();
  if (kSanitized) return;  // accuracy is for the Release build
  for (std::size_t i = 0; i < kLidarPoseParams; ++i) {
    EXPECT_FALSE(r.observability.poorly_constrained[i]) << lidarPoseParamName(LidarPoseParam(i));
  }
  EXPECT_LT(e.translation_m, 0.02);
  EXPECT_LT(e.rotation_deg, 0.1);
  EXPECT_LT(e.time_ms, 1.0);
  EXPECT_LT(r.final_cost, r.initial_cost);
}

INSTANTIATE_TEST_SUITE_P(Seeds, LidarPoseOnSimulatedPoseScenario, ::testing::Values(4u, 11u, 23u));

TEST(LidarPoseOnSimulatedPoseScenario, RepeatedRunsAreBitIdentical) {
  const SimRun run = simulatePose(4, kSanitized ? 3.0 : 6.0);
  const PoseTrajectory trajectory(run.poses);
  LidarPoseSettings settings = testSettings();
  const LidarPoseResult a = calibrateLidarPose(run.scans, trajectory, settings);
  const SimRun again = simulatePose(4, kSanitized ? 3.0 : 6.0);
  const LidarPoseResult b = calibrateLidarPose(again.scans, PoseTrajectory(again.poses), settings);
  EXPECT_GT(a.local_evaluations, kSanitized ? 10u : 20u);
  EXPECT_TRUE(bitIdentical(a, b)) << "a second simulation + calibration differs";
  settings.threads = 1;
  EXPECT_TRUE(bitIdentical(a, calibrateLidarPose(run.scans, trajectory, settings))) << "1 thread differs";
}

}  // namespace
}  // namespace rigcal::calib
