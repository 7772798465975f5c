// What a parking-lot calibration hands on besides the extrinsics (the simulator's datasets, no pipeline): the
// base lidar's height, roll and pitch from the simulated ground, and the output files of a real run, whose
// after clouds must sit on the map.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "lidar_lidar_sim_suite.hpp"
#include "rigcal/calib/base_lidar/base_lidar_calibration.hpp"
#include "rigcal/calib/outputs/calibration_yaml_writer.hpp"
#include "rigcal/calib/outputs/cloud_writers.hpp"
#include "rigcal/calib/outputs/overview_png_writer.hpp"
#include "rigcal/calib/outputs/report_json_writer.hpp"
#include "rigcal/calib/outputs/summary_table.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/registration/evaluator.hpp"
#include "sanitizers.hpp"
#include "test_data.hpp"

namespace rigcal::calib {
namespace {

TEST_F(LidarLidarSim, BaseLidarZRollPitchFromTheSimulatedGround) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation-heavy: Release only (the accuracy test exercises the same code instrumented)";
  config::Parameters params = data().params;
  params.base_lidar_max_inlier_distance = 0.03;  // 2 cm range noise and 4 cm bumps
  // The ground near the car: the lot's 1.2 % slope and bumps bend the plane further out.
  params.base_lidar_crop_box_min_x = params.base_lidar_crop_box_min_y = -8.0;
  params.base_lidar_crop_box_max_x = params.base_lidar_crop_box_max_y = 8.0;
  const Pose truth = data().truth_T_base_mapping;
  const Pose guess = test::perturb(truth, 0.3, 5.0, 99);
  const auto r = calibrateBaseLidar(data().ground_cloud_mapping, guess, params);
  ASSERT_TRUE(r.ok) << r.failure;
  const XyzRpy got = toXyzRpy(r.T_base_lidar), want = toXyzRpy(truth);
  std::printf("base-lidar: z %.4f (truth %.4f), roll %.4f deg (%.4f), pitch %.4f deg (%.4f)\n", got.z, want.z,
              rad2deg(got.roll), rad2deg(want.roll), rad2deg(got.pitch), rad2deg(want.pitch));
  EXPECT_NEAR(got.z, want.z, 0.01);
  EXPECT_NEAR(rad2deg(got.roll), rad2deg(want.roll), 0.05);
  EXPECT_NEAR(rad2deg(got.pitch), rad2deg(want.pitch), 0.05);
}

TEST_F(LidarLidarSim, OutputsOfARealRunPutTheAfterCloudOnTheMap) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "wall-clock budget measured in the optimised build only";
  config::Parameters params = data().params;
  params.calibration_deadline_s = 4.0;
  CalibrationOutcome o;
  o.rig_name = "sim-parking-lot";
  o.mapping_sensor = data().datasets.front().mapping_sensor;
  o.version = "test";
  o.deadline_s = params.calibration_deadline_s;
  o.initial_T_base_sensor[o.mapping_sensor] = data().truth_T_base_mapping;
  for (const auto& d : data().datasets)
    o.initial_T_base_sensor[d.calibration_sensor] = data().truth_T_base_mapping * d.T_mapping_calib_guess;
  o.datasets = data().datasets;
  o.lidars = calibrateInTurn(o.datasets, params);
  test::TempDir dir;
  // RIGCAL_KEEP_OUTPUTS=<dir>: write there instead, to look at them.
  const char* keep = std::getenv("RIGCAL_KEEP_OUTPUTS");
  const std::filesystem::path out = keep != nullptr ? std::filesystem::path(keep) : dir.path();
  std::filesystem::create_directories(out);
  writeCalibrationYaml(out / "calibration.yaml", o);
  writeReportJson(out / "report.json", o);
  writeCalibrationClouds(out, o);
  writeOverviewPng(out / "overview.png", o);
  std::printf("%s", summaryTable(o).c_str());
  // The after clouds sit on the map far better than the before clouds.
  const auto map = readPcd(out / "map.pcd");
  const registration::Target target(registration::fromTable(map));
  for (const auto& d : o.datasets) {
    const auto before = registration::evaluate(target, registration::fromTable(readPcd(out / (d.calibration_sensor + "_before.pcd"))),
                                               Pose::Identity(), 0.1);
    const auto after = registration::evaluate(target, registration::fromTable(readPcd(out / (d.calibration_sensor + "_after.pcd"))),
                                              Pose::Identity(), 0.1);
    std::printf("%s on the map: inliers %.3f -> %.3f\n", d.calibration_sensor.c_str(), before.inlier_ratio, after.inlier_ratio);
    EXPECT_GT(after.inlier_ratio, before.inlier_ratio + 0.2) << d.calibration_sensor;
  }
  EXPECT_GT(std::filesystem::file_size(out / "overview.png"), 10000u);
}

}  // namespace
}  // namespace rigcal::calib
