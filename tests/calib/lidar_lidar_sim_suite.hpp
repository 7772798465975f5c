#pragma once
// What the parking-lot lidar-lidar suites share: their fixture (the flat stretch of the parking lot, built on
// first use and let go after the suite) and their way of calibrating several lidars, one after another under
// one deadline. Not in an anonymous namespace: the suite's tests live in several files, on one fixture class.
#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_worker.hpp"

namespace rigcal::calib {

/// The calibration lidars one after the other, sharing params.calibration_deadline_s from now through a
/// CalibrationBudget (what the lidar-lidar worker does as the datasets arrive).
inline std::vector<LidarLidarResult> calibrateInTurn(const std::vector<pipeline::CalibrationDataset>& datasets,
                                                     const config::Parameters& params) {
  CalibrationBudget budget(std::chrono::steady_clock::now(), params.calibration_deadline_s, datasets.size());
  std::vector<LidarLidarResult> results;
  for (const auto& d : datasets) {
    const auto share = budget.next();
    results.push_back(calibrateLidarLidar(d, params, share, optionsForShare({}, budget)));
  }
  return results;
}

class LidarLidarSim : public ::testing::Test {
 protected:
  static const test::SimDatasets& data() { return test::flatParkingLot(); }
  static void TearDownTestSuite() { test::releaseFlatParkingLot(); }

  static double translationError(const Pose& a, const Pose& b) { return (a.translation() - b.translation()).norm(); }
  static double rotationErrorDeg(const Pose& a, const Pose& b) { return rad2deg(rotationAngleBetween(a, b)); }
};

}  // namespace rigcal::calib
