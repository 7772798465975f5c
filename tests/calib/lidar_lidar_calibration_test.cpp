// Lidar-lidar calibration on simulator data (tests/calib/lidar_lidar_sim_dataset.*): accuracy from a
// 0.3 m / 5° guess, determinism, the deadline, several lidars sharing it, a frame that contradicts the others,
// and bad input. What the calibration hands on (base lidar, output files): lidar_lidar_sim_outputs_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "lidar_lidar_sim_suite.hpp"
#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/calibration_deskew.hpp"
#include "rigcal/calib/lidar_lidar/calibration_source.hpp"
#include "rigcal/calib/lidar_lidar/ensemble_plan.hpp"
#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/calib/lidar_lidar/calibration_score.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_verdict.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_worker.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"
#include "sanitizers.hpp"

namespace rigcal::calib {
namespace {

using Clock = std::chrono::steady_clock;

TEST_F(LidarLidarSim, EachCalibrationLidarWithinOneCentimetreAndFiveHundredthsOfADegree) {
  config::Parameters params = data().params;
  params.calibration_deadline_s = RIGCAL_SANITIZED ? 600.0 : 60.0;  // accuracy, not the budget, is tested here
  ASSERT_EQ(data().datasets.size(), 2u);
  for (const auto& d : data().datasets) {
    const Pose truth = data().truth_T_mapping_calib.at(d.calibration_sensor);
    ASSERT_NEAR(translationError(d.T_mapping_calib_guess, truth), 0.3, 1e-9);
    ASSERT_NEAR(rotationErrorDeg(d.T_mapping_calib_guess, truth), 5.0, 1e-6);
    LidarLidarOptions quick;  // the exhaustive pass only spends leftover time; accuracy comes before it
    quick.exhaustive = false;
    const auto r = calibrateLidarLidar(d, params, registration::Deadline::after(std::chrono::seconds(600)), quick);
    ASSERT_TRUE(r.ok) << d.calibration_sensor << ": " << r.failure;
    EXPECT_FALSE(r.deadline_reached);
    EXPECT_EQ(r.frames_used.size(), d.frames.size());
    EXPECT_LT(r.final_score.value, r.initial_score.value);
    EXPECT_TRUE(std::isfinite(r.final_score.value));
    const double dt = translationError(r.T_mapping_calib, truth);
    const double dr = rotationErrorDeg(r.T_mapping_calib, truth);
    std::printf("%s: error %.4f m %.4f deg, score %.6f -> %.6f m2 (inliers %.3f -> %.3f), %.2f s, %zu runs\n",
                d.calibration_sensor.c_str(), dt, dr, r.initial_score.value, r.final_score.value,
                r.initial_score.inlier_ratio, r.final_score.inlier_ratio, r.seconds, r.runs.size());
    for (const auto& [stage, seconds] : r.stage_seconds) std::printf("  %s %.3f s\n", stage.c_str(), seconds);
    // Every frame confirmed on its source re-deskewed with the result, which is what the verdict judges by.
    for (const std::size_t f : r.frames_used) {
      const bool confirmed = std::any_of(r.runs.begin(), r.runs.end(), [&](const RegistratorRun& run) {
        return run.frame == int(f) && run.redeskewed && run.frame_score >= 0;
      });
      EXPECT_TRUE(confirmed) << d.calibration_sensor << " frame " << f << " has no re-deskewed registration";
    }
    if (!RIGCAL_SANITIZED) {
      EXPECT_LT(dt, 0.01) << d.calibration_sensor;
      EXPECT_LT(dr, 0.05) << d.calibration_sensor;
    } else {  // two frames only
      EXPECT_LT(dt, 0.03) << d.calibration_sensor;
      EXPECT_LT(dr, 0.15) << d.calibration_sensor;
    }
  }
}

TEST_F(LidarLidarSim, EveryRegistratorConvergesFromTheGuessWithinItsIterations) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation-heavy: Release only (the accuracy test exercises the same code instrumented)";
  // The ensemble's tolerances are tight (1e-5 m / 1e-6 rad, 200 iterations): a registrator that runs out
  // of iterations instead of converging wastes the budget (the coarse-to-fine subsample once did).
  SourceOptions so;
  so.num_threads = 2;
  AugmentedTargetOptions to;
  to.num_threads = 2;
  for (const auto& d : data().datasets) {
    for (std::size_t f = 0; f < d.frames.size(); ++f) {
      const registration::PointCloud source = buildSource(*d.frames[f].deskewed, data().params, so);
      const auto target = buildAugmentedTarget(d, f, source, data().params, to).target;
      for (const Registrator r : perFrameRegistrators()) {
        const auto res = runRegistrator(r, *target, source, d.T_mapping_calib_guess, data().params, 2,
                                        registration::Deadline::never());
        EXPECT_EQ(res.status, registration::Status::kConverged)
            << d.calibration_sensor << " frame " << f << ", " << toString(r) << ": " << res.reason;
      }
    }
  }
}

// The crop of a frame's mapping clouds is the step a short deadline used to overrun on a busy machine:
// it stops between clouds once the deadline has passed (and a cancel token stops it the same way).
TEST_F(LidarLidarSim, AnExpiredDeadlineStopsTheTargetCrop) {
  const auto& d = data().datasets.front();
  const registration::PointCloud source = buildSource(*d.frames.front().deskewed, data().params, SourceOptions{});
  AugmentedTargetOptions to;
  EXPECT_GT(augmentedCloud(d, 0, source, data().params, to).size(), 100u) << "the frame has a target";
  to.deadline = registration::Deadline::after(std::chrono::seconds(-1));
  EXPECT_TRUE(augmentedCloud(d, 0, source, data().params, to).empty());
  registration::CancelToken token;
  token.cancel();
  to.deadline = registration::Deadline::never(&token);
  EXPECT_TRUE(augmentedCloud(d, 0, source, data().params, to).empty());
}

TEST_F(LidarLidarSim, RepeatedRunsGiveIdenticalResults) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation-heavy: Release only (the accuracy test exercises the same code instrumented)";
  config::Parameters params = data().params;
  auto d = data().datasets.front();
  d.frames.resize(2);  // half the work: determinism does not need every frame
  const auto deadline = registration::Deadline::after(std::chrono::seconds(600));
  LidarLidarOptions two_threads, one_thread;
  two_threads.exhaustive = one_thread.exhaustive = false;  // a run that ends by itself, not by the clock
  two_threads.trajectory_clock = one_thread.trajectory_clock = true;
  one_thread.num_threads = 1;
  const auto a = calibrateLidarLidar(d, params, deadline, two_threads);
  const auto b = calibrateLidarLidar(d, params, deadline, one_thread);
  ASSERT_TRUE(a.ok) << a.failure;
  ASSERT_FALSE(a.deadline_reached);
  ASSERT_FALSE(b.deadline_reached);
  EXPECT_TRUE(a.T_mapping_calib.matrix() == b.T_mapping_calib.matrix())
      << a.T_mapping_calib.matrix() << "\nvs\n" << b.T_mapping_calib.matrix();
  EXPECT_EQ(a.final_score.value, b.final_score.value);
  EXPECT_EQ(a.runs.size(), b.runs.size());
  ASSERT_NE(a.trajectory_clock.status, TrajectoryClockEstimate::Status::kNotRun);
  EXPECT_EQ(a.trajectory_clock.status, b.trajectory_clock.status);
  EXPECT_EQ(a.trajectory_clock.offset_ms, b.trajectory_clock.offset_ms);
  EXPECT_EQ(a.trajectory_clock.profile, b.trajectory_clock.profile) << "its residual passes, on 2 threads or 1";
}

// After a complete plan the searches for another basin use `search_share` of the time left and no more:
// the rest goes to the lidars still to come (LidarLidarWorker: none while others wait).
TEST_F(LidarLidarSim, TheSearchesForAnotherBasinKeepToTheirShare) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "wall-clock bounds measured in the optimised build only";
  config::Parameters params = data().params;
  auto d = data().datasets.front();
  d.frames.resize(2);  // a plan far shorter than the share
  constexpr double kShare = 4.0;  // s
  const auto run = [&](double search_share) {
    LidarLidarOptions o;
    o.search_share = search_share;
    o.trajectory_clock = true;
    const auto r = calibrateLidarLidar(d, params, registration::Deadline::after(std::chrono::seconds(4)), o);
    std::printf("search_share %.1f: %.3f s of %.1f, %zu runs\n", search_share, r.seconds, kShare, r.runs.size());
    return r;
  };
  const auto none = run(0.0), half = run(0.5), all = run(1.0);
  for (const LidarLidarResult* r : {&none, &half, &all}) {
    ASSERT_TRUE(r->ok) << r->failure;
    EXPECT_FALSE(r->deadline_reached) << "the searches' end is not a cut plan";
    EXPECT_NE(r->trajectory_clock.status, TrajectoryClockEstimate::Status::kNotRun);
  }
  const double plan = none.seconds;  // the plan and the clock estimate, no search
  // On a machine loaded beyond what this test can judge (the plan alone took 2.96 s of the 4 s once, beside
  // the shared-memory driver processes' test under ctest -j 2) there is no search to bound: nothing to say.
  if (plan >= 0.6 * kShare) GTEST_SKIP() << "the plan took " << plan << " s of " << kShare << ": no time left to search";
  // (Bounds for a Release ctest -j 2: one registration of the search may overrun its end by ~0.2 s.)
  EXPECT_LT(half.seconds, plan + 0.5 * (kShare - plan) + 0.4) << "half of what the plan left, no more";
  EXPECT_GT(half.runs.size(), none.runs.size()) << "it did search";
  // The whole share, unless the exhaustive pass ran out of untried starts first (3.5-3.7 s on a quiet machine).
  EXPECT_GE(all.runs.size(), half.runs.size());
  EXPECT_LE(all.seconds, kShare + 0.05);
}

// The re-deskew and its batched chain come right after the first chain, before the other frames'
// ensembles: when the deadline cuts the plan under load, it cuts those ensembles, not the re-deskew (worth
// 0.63 -> 0.02 cm for the parking lot's front_right at load 8).
TEST_F(LidarLidarSim, TheReDeskewComesBeforeTheOtherFramesEnsembles) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation-heavy: Release only (the accuracy test exercises the same code instrumented)";
  config::Parameters params = data().params;
  auto d = data().datasets.front();
  d.frames.resize(3);
  LidarLidarOptions o;
  o.exhaustive = false;
  const auto r = calibrateLidarLidar(d, params, registration::Deadline::after(std::chrono::seconds(600)), o);
  ASSERT_TRUE(r.ok) << r.failure;
  ASSERT_FALSE(r.deadline_reached);
  ASSERT_GE(r.frames_used.size(), 2u);
  std::size_t batched_before = 0;
  bool later_ensemble = false;
  for (const auto& run : r.runs) {
    if (run.frame >= 1 && run.registrator == "ndt") {
      later_ensemble = true;
      break;
    }
    if (run.registrator == "batched_icp") ++batched_before;
  }
  EXPECT_TRUE(later_ensemble) << "the other frames' ensembles ran";
  // The first chain (3 distances) and the re-deskew's chain from the best (3 more).
  EXPECT_GE(batched_before, 2 * batchedDistances(params).size());
}

// One frame's target placed 8 cm off (its mapping pose at the scan stamp moved, as a slid or mis-posed
// augmented cloud would be): its own registrations land there, the other three agree, and the result must not
// be the compromise the all-frames score makes (1.44 cm off with the frame kept in; 0.16 cm set aside).
TEST_F(LidarLidarSim, AFrameThatContradictsTheOthersIsSetAsideNotAveragedIn) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation-heavy: Release only (the accuracy test exercises the same code instrumented)";
  const config::Parameters& params = data().params;
  auto d = data().datasets.front();
  ASSERT_GE(d.frames.size(), 4u);
  const std::size_t moved = d.frames.size() - 1;
  d.frames[moved].pairing.T_map_mapping_at_scan.pretranslate(Eigen::Vector3d(0.0, 0.08, 0.0));
  LidarLidarOptions o;
  o.exhaustive = false;
  const auto r = calibrateLidarLidar(d, params, registration::Deadline::after(std::chrono::seconds(600)), o);
  ASSERT_TRUE(r.ok) << r.failure;
  ASSERT_FALSE(r.deadline_reached);
  EXPECT_EQ(r.frames_set_aside, std::vector<std::size_t>{moved});
  const Pose truth = data().truth_T_mapping_calib.at(d.calibration_sensor);
  const double dt = translationError(r.T_mapping_calib, truth), dr = rotationErrorDeg(r.T_mapping_calib, truth);
  std::printf("one frame 8 cm off, set aside: error %.4f m %.4f deg\n", dt, dr);
  EXPECT_LT(dt, 0.005);
  EXPECT_LT(dr, 0.03);
  EXPECT_EQ(r.evidence.frames_registered - r.evidence.frames_agreeing, 1u) << "the verdict counts it against";
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.doubt;

  // The same frames as they are: nothing to set aside.
  const auto clean = calibrateLidarLidar(data().datasets.front(), params,
                                         registration::Deadline::after(std::chrono::seconds(600)), o);
  EXPECT_TRUE(clean.frames_set_aside.empty());
}

TEST_F(LidarLidarSim, OneSecondDeadlineReturnsTheBestSoFarInTime) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "wall-clock bound measured in the optimised build only";
  config::Parameters params = data().params;
  const auto& d = data().datasets.front();
  const auto start = Clock::now();
  const auto r = calibrateLidarLidar(d, params, registration::Deadline::after(std::chrono::seconds(1)));
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("1 s deadline: returned after %.3f s, deadline_reached %d, ok %d, %zu runs, score %.6f -> %.6f\n",
              elapsed, int(r.deadline_reached), int(r.ok), r.runs.size(), r.initial_score.value, r.final_score.value);
  for (const auto& [stage, seconds] : r.stage_seconds) std::printf("  %s %.3f s\n", stage.c_str(), seconds);
  for (const auto& run : r.runs)
    std::printf("  %s frame %d: %.3f s, %s, frame score %.6f\n", run.registrator.c_str(), run.frame, run.seconds,
                run.status.c_str(), run.frame_score);
  EXPECT_LT(elapsed, 1.05);
  EXPECT_TRUE(r.deadline_reached);
  EXPECT_TRUE(r.ok) << r.failure;  // the best so far already beats the guess
  EXPECT_TRUE(r.T_mapping_calib.matrix().allFinite());
  const Pose truth = data().truth_T_mapping_calib.at(d.calibration_sensor);
  EXPECT_LT(translationError(r.T_mapping_calib, truth), translationError(d.T_mapping_calib_guess, truth));
}

TEST_F(LidarLidarSim, SeveralLidarsShareTheDeadlineFairly) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "wall-clock bound measured in the optimised build only";
  config::Parameters params = data().params;
  params.calibration_deadline_s = 2.0;
  const auto start = Clock::now();
  const auto results = calibrateInTurn(data().datasets, params);
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_EQ(results.size(), 2u);
  std::printf("2 lidars, 2 s: %.3f s total; %s %.3f s, %s %.3f s\n", elapsed, results[0].calibration_sensor.c_str(),
              results[0].seconds, results[1].calibration_sensor.c_str(), results[1].seconds);
  EXPECT_LT(elapsed, 2.1);
  for (const auto& r : results) EXPECT_TRUE(r.ok) << r.calibration_sensor << ": " << r.failure;
  // The lidars run one after the other: the first may use its half of the budget and no more; the second
  // gets what is left. (A run also stops early when its next step would not fit in its share, so a lower
  // bound on the first one's time depends on how fast this machine is.)
  EXPECT_LT(results[0].seconds, 1.05) << "the first lidar keeps to its half of the budget";
  EXPECT_LT(results[0].seconds + results[1].seconds, 2.1);
}

TEST_F(LidarLidarSim, BadInputsGiveClearOneLineErrors) {
  const config::Parameters params = data().params;
  const auto& good = data().datasets.front();
  const auto failWith = [&](pipeline::CalibrationDataset d, const std::string& needle) {
    const auto r = calibrateLidarLidar(d, params, registration::Deadline::after(std::chrono::seconds(5)));
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.failure.find(needle), std::string::npos) << r.failure;
    EXPECT_EQ(r.failure.find('\n'), std::string::npos);
    EXPECT_TRUE(r.T_mapping_calib.matrix().allFinite());
  };
  auto d = good;
  d.frames.clear();
  failWith(d, "no selected calibration frames");
  d = good;
  d.frames.resize(1);
  failWith(d, "1 of 2 frames");
  d = good;
  d.T_mapping_calib_guess.translation().x() = std::nan("");
  failWith(d, "T_mapping_calib_guess");
  d = good;
  d.frames[1].raw.reset();
  failWith(d, "frames[1] has no raw scan");
  d = good;
  d.frames[0].pairing.keyframe_frame = d.trajectory.size() + 3;
  failWith(d, "frames[0].pairing.keyframe_frame");
  d = good;
  d.trajectory.resize(1);
  failWith(d, "fewer than two poses");
  d = good;
  d.mapping_clouds.clear();
  failWith(d, "no mapping clouds");
  // Clouds that do not overlap at all: every frame is skipped, no NaN, a failure that says why.
  d = good;
  for (auto& f : d.frames) {
    auto far = std::make_shared<Scan>(*f.deskewed);
    for (auto& z : far->z) z += 5000.0F;
    f.deskewed = far;
  }
  failWith(d, "no calibration frame has a usable source and target");
}

TEST(CalibrationScore, FiniteWhenNothingCorresponds) {
  registration::PointCloud target_cloud, source;
  for (int i = 0; i < 200; ++i) {
    target_cloud.add(i * 0.1, 0, 0);
    source.add(i * 0.1, 100, 0);
  }
  const registration::Target target(target_cloud);
  const auto s = scoreFrame(target, source, Pose::Identity(), 0.1);
  EXPECT_TRUE(std::isfinite(s.value));
  EXPECT_DOUBLE_EQ(s.value, 0.01);  // every point costs d_max²
  EXPECT_EQ(s.inliers, 0u);
  const auto aligned = scoreFrame(target, source, Pose(Eigen::Translation3d(0, -100, 0)), 0.1);
  EXPECT_TRUE(aligned.betterThan(s));
  EXPECT_EQ(aligned.inliers, 200u);
}

TEST_F(LidarLidarSim, RedeskewWithTheTrueExtrinsicMatchesTheTruth) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation-heavy: Release only (the accuracy test exercises the same code instrumented)";
  // The dataset's sweeps were deskewed with the wrong guess; with the truth the same raw sweep must
  // move differently than with the guess, and the two deskews must agree at the sweep start.
  const auto& d = data().datasets.front();
  const Pose truth = data().truth_T_mapping_calib.at(d.calibration_sensor);
  const auto& raw = *d.frames.back().raw;
  const Scan with_truth = deskewThroughMapping(raw, d.trajectory, truth);
  const Scan with_guess = deskewThroughMapping(raw, d.trajectory, d.T_mapping_calib_guess);
  ASSERT_EQ(with_truth.size(), raw.size());
  double max_diff = 0.0, first_diff = 0.0;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const double diff = std::hypot(with_truth.x[i] - with_guess.x[i], with_truth.y[i] - with_guess.y[i],
                                   with_truth.z[i] - with_guess.z[i]);
    max_diff = std::max(max_diff, diff);
    if (raw.offset_ns[i] < 100'000) first_diff = std::max(first_diff, diff);
  }
  EXPECT_GT(max_diff, 1e-3);   // the guess's lever arm bends the sweep differently
  EXPECT_LT(first_diff, 1e-3); // both are exact at the reference time
  EXPECT_THROW(mappingPoseAt({}, 0), std::invalid_argument);
}

}  // namespace
}  // namespace rigcal::calib
