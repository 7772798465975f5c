// Issue 19's unusual mounts on simulator data (tests/calib/lidar_lidar_sim_dataset.*, no pipeline): the
// container-yard presets' calibration lidars, each from a guess 0.3 m / 5° off, must land within 1 cm /
// 0.05° of the truth and be confirmed (`ok`) by their own evidence:
//   yard-corners: VLP-32C maps (a 32-beam map); VLP-16 corners yawed ±45° and pitched 15° down, a rear VLP-16
//                 yawed 180° and pitched 20° down;
//   yard-side:    OS1-64 maps; a VLP-32C rolled 90° and a VLP-16 rolled −90° (spin axes horizontal).
// Accuracy is tested with a deadline that does not bind (under the sanitizers: shorter drive, fewer frames,
// behaviour only); the default deadline shared by all lidars is tested in Release (the verdict must be honest:
// within the goal when `ok`, else `unverified` with a suggested --deadline). Numbers measured: see the report of
// branch `mounts` and the comments at each test.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <memory>

#include "lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_verdict.hpp"
#include "rigcal/pipeline/calibration_crop.hpp"
#include "rigcal/pipeline/frame_selector.hpp"
#include "sanitizers.hpp"

namespace rigcal::calib {
namespace {

using Clock = std::chrono::steady_clock;

double translationError(const Pose& a, const Pose& b) { return (a.translation() - b.translation()).norm(); }
double rotationErrorDeg(const Pose& a, const Pose& b) { return rad2deg(rotationAngleBetween(a, b)); }

/// The first seconds of the preset's drive (the start and the straight towards the first turn), built once
/// per preset for both tests.
const test::SimDatasets& yardDatasets(const std::string& scenario) {
  static std::map<std::string, std::unique_ptr<test::SimDatasets>> cache;
  auto& d = cache[scenario];
  if (!d) {
    test::SimDatasetOptions o;
    o.scenario = scenario;
    o.seconds = 10.0;
    o.frames = 3;
    auto data = test::buildSimDatasets(o);
    // The pairing lane's crop, as `rigcal calibrate` applies it before frame selection (the simulator's
    // datasets skip the pipeline).
    for (auto& ds : data.datasets)
      for (auto& f : ds.frames) {
        auto cropped = std::make_shared<Scan>(*f.deskewed);
        pipeline::cropCalibrationCloud(*cropped, ds.T_mapping_calib_guess, data.params);
        f.information = pipeline::pcaInformation(*cropped);
        f.deskewed = std::move(cropped);
      }
    d = std::make_unique<test::SimDatasets>(std::move(data));
  }
  return *d;
}

struct Row {
  std::string sensor;
  double dt_cm, dr_deg, seconds;
  std::size_t frames, runs;
  double inlier_ratio;
  Verdict verdict;
};

Row calibrateOne(const test::SimDatasets& data, const pipeline::CalibrationDataset& d, const config::Parameters& params,
                 const registration::Deadline& deadline, double deadline_s, const LidarLidarOptions& options = {}) {
  auto r = calibrateLidarLidar(d, params, deadline, options);
  judgeLidarLidar(r, d.frames.size(), deadline_s);
  const Pose& truth = data.truth_T_mapping_calib.at(d.calibration_sensor);
  Row row{d.calibration_sensor,
          100 * translationError(r.T_mapping_calib, truth),
          rotationErrorDeg(r.T_mapping_calib, truth),
          r.seconds,
          r.frames_used.size(),
          r.runs.size(),
          r.final_score.inlier_ratio,
          r.verdict};
  std::printf("%-13s %-11s error %.3f cm %.4f deg  (guess %.1f cm %.2f deg)  frames %zu/%zu  registrations %zu  "
              "inliers %.2f  %.2f s%s%s\n",
              d.calibration_sensor.c_str(), toString(r.verdict), row.dt_cm, row.dr_deg,
              100 * translationError(d.T_mapping_calib_guess, truth), rotationErrorDeg(d.T_mapping_calib_guess, truth),
              row.frames, d.frames.size(), row.runs, row.inlier_ratio, row.seconds,
              r.doubt.empty() ? "" : "  doubt: ", r.doubt.c_str());
  EXPECT_TRUE(r.ok) << d.calibration_sensor << ": " << r.failure;
  return row;
}

class LidarLidarMounts : public ::testing::TestWithParam<const char*> {};

// Accuracy and evidence with a deadline that does not bind. Measured (Release, load 17 on 2 cores):
//   yard-corners  corner_left 0.32 cm 0.009°, corner_right 0.04 cm 0.008°, rear 0.02 cm 0.001°, all ok,
//                 3 frames, 26 registrations each, inlier ratio 0.65-0.66;
//   yard-side     side_left 0.45 cm 0.023°, side_right 5.6 cm 0.20° (10 s of straight drive between container
//                 rows; 20 s with the first turn: 0.47 cm 0.025° and 0.15 cm 0.024°), both unverified: inlier
//                 ratio 0.28-0.30 and frames 24 cm apart. A sideways lidar looks at the strip beside the vehicle
//                 that the roof lidar's blind circle hides on a straight drive. These 10 s hold the side rig to
//                 an honest verdict (never ok when off the goal), the corners to the goal; the whole drive, turns
//                 included, put every lidar of both rigs within the goal, quiet and beside one busy loop
//                 (calibrate_yard_test.cpp, long).
TEST_P(LidarLidarMounts, EveryCalibrationLidarWithinTheGoalFromAThirtyCentimetreFiveDegreeGuess) {
  // Whole calibrations without a deadline: minutes under the sanitizers, which see the same code paths in
  // rigcal_lidar_lidar_tests.
  if (test::kSanitized) GTEST_SKIP() << "accuracy of unbounded calibrations: Release only";
  const bool side = std::string(GetParam()) == "yard-side";
  const auto& data = yardDatasets(GetParam());
  ASSERT_GE(data.datasets.size(), 2u);
  LidarLidarOptions quick;  // the exhaustive pass only spends leftover time; accuracy comes before it
  quick.exhaustive = false;
  for (const auto& d : data.datasets) {
    const Row row =
        calibrateOne(data, d, data.params, registration::Deadline::after(std::chrono::seconds(900)), 900, quick);
    const bool within = row.dt_cm < 1.0 && row.dr_deg < 0.05;
    if (row.verdict == Verdict::kOk) {
      EXPECT_TRUE(within) << row.sensor << " is called ok off the goal";
    }
    if (side) continue;
    EXPECT_TRUE(within) << row.sensor;
    EXPECT_EQ(row.verdict, Verdict::kOk) << row.sensor;
  }
}

// The default calibration_deadline_s shared by every calibration lidar (what `rigcal calibrate` does): the
// verdict must not lie. A lidar called ok is within the goal; one the deadline cut is unverified, never a
// wrong ok. Measured (Release, load 17): yard-corners before the first-target fix (lidar_lidar_frames.cpp)
// 0 of 3 ok, 1 frame each, inlier ratio 0.43-0.50, rear 4.55 cm off; after: 1 of 3 ok, 1-3 frames, inlier
// ratio 0.49-0.62, all within 0.62 cm / 0.014° (a second run: 0 of 3 ok, rear's first frame 4.55 cm again
// when the target could not be thinned enough). yard-side: 0 of 2 ok (inlier ratio 0.29-0.30).
TEST_P(LidarLidarMounts, UnderTheDefaultDeadlineOkMeansWithinTheGoal) {
  if (!test::kWallClockAsserted) GTEST_SKIP() << "deadline-bound: Release only";
  const auto& data = yardDatasets(GetParam());
  config::Parameters params = data.params;
  params.calibration_deadline_s = config::Parameters{}.calibration_deadline_s;
  CalibrationBudget budget(Clock::now(), params.calibration_deadline_s, data.datasets.size());
  const auto t0 = Clock::now();
  int ok = 0;
  for (const auto& d : data.datasets) {
    const Row row = calibrateOne(data, d, params, budget.next(), params.calibration_deadline_s);
    if (row.verdict == Verdict::kOk) {
      ++ok;
      EXPECT_LT(row.dt_cm, 1.0) << row.sensor << " is called ok";
      EXPECT_LT(row.dr_deg, 0.05) << row.sensor << " is called ok";
    } else {
      EXPECT_EQ(row.verdict, Verdict::kUnverified) << row.sensor;
    }
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf("%s: %d of %zu ok within the default %.0f s deadline (%.1f s)\n", GetParam(), ok, data.datasets.size(),
              params.calibration_deadline_s, elapsed);
  EXPECT_LT(elapsed, 1.05 * params.calibration_deadline_s + 1.0);
}

INSTANTIATE_TEST_SUITE_P(Yard, LidarLidarMounts, ::testing::Values("yard-corners", "yard-side"),
                         [](const ::testing::TestParamInfo<const char*>& p) { return std::string(p.param) == "yard-corners" ? "Corners" : "Side"; });

}  // namespace
}  // namespace rigcal::calib
