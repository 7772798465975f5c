// The whole chain in process: simulator → Pipeline (mapping, pairing, selection) → its CalibrationDatasets
// → lidar-lidar calibration within the default deadline, checked against the simulator's truth.
// ~20 s of parking-lot: a long test (tens of CPU seconds), so it runs only with RIGCAL_LONG_TESTS=1.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "../pipeline/sim_pipeline_util.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"
#include "rigcal/sim/scenario.hpp"
#include "sanitizers.hpp"

namespace rigcal::calib {
namespace {

TEST(PipelineCalibration, ParkingLotDatasetsCalibrateToTheTruth) {
  if (std::getenv("RIGCAL_LONG_TESTS") == nullptr || RIGCAL_SANITIZED)
    GTEST_SKIP() << "long test: set RIGCAL_LONG_TESTS=1 (Release only)";
  sim::Scenario scenario = sim::loadScenario("parking-lot");
  auto& segments = scenario.trajectory.segments;
  if (!segments.empty() && segments.front().kind == sim::TrajectorySegment::Kind::kStop) segments.erase(segments.begin());
  const sim::Simulation simulation(scenario);
  ::rigcal::test::TempDir dir;
  config::RigConfig rig = pipeline::test::rigFor(simulation, dir.path());
  const auto run = pipeline::test::runInProcess(simulation, rig, 20.0);
  for (const auto& s : run.shortfalls) std::printf("shortfall: %s\n", s.message.c_str());
  ASSERT_FALSE(run.datasets.empty());
  const std::size_t mapping = scenario.sensorIndex(scenario.mapping_lidar);
  for (const auto& d : run.datasets) {
    const std::size_t ci = scenario.sensorIndex(d->calibration_sensor);
    const Pose truth = scenario.sensors[mapping].T_base_sensor.inverse() * scenario.sensors[ci].T_base_sensor;
    const auto r = calibrateLidarLidar(*d, rig.parameters,
                                       registration::Deadline::after(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                           std::chrono::duration<double>(rig.parameters.calibration_deadline_s))));
    const double dt = (r.T_mapping_calib.translation() - truth.translation()).norm();
    const double dr = rad2deg(rotationAngleBetween(r.T_mapping_calib, truth));
    const double dt0 = (d->T_mapping_calib_guess.translation() - truth.translation()).norm();
    const double dr0 = rad2deg(rotationAngleBetween(d->T_mapping_calib_guess, truth));
    std::printf("%s: %zu frames, guess off %.3f m %.2f deg -> error %.4f m %.4f deg, score %.6f -> %.6f, %.2f s%s\n",
                d->calibration_sensor.c_str(), d->frames.size(), dt0, dr0, dt, dr, r.initial_score.value,
                r.final_score.value, r.seconds, r.deadline_reached ? " (deadline)" : "");
    EXPECT_TRUE(r.ok) << r.failure;
    EXPECT_LT(dt, 0.01) << d->calibration_sensor;
    EXPECT_LT(dr, 0.05) << d->calibration_sensor;
  }
}

}  // namespace
}  // namespace rigcal::calib
