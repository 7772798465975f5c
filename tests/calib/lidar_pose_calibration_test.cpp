// End-to-end lidar-pose calibration on a synthetic recording with a known extrinsic and time offset.
#include <gtest/gtest.h>

#include <cstring>
#include <iostream>

#include "lidar_pose_synthetic.hpp"
#include "rigcal/calib/lidar_pose/lidar_pose_calibration.hpp"
#include "sanitizers.hpp"

namespace rigcal::calib {
namespace {

using test::kSanitized;

struct Errors {
  double translation_m, rotation_deg, time_ms;
};

Errors errorsOf(const LidarPoseResult& r, const test::SyntheticOptions& o) {
  return {(r.T_pose_lidar.translation() - o.T_pose_lidar.translation()).norm(),
          rad2deg(rotationAngleBetween(r.T_pose_lidar, o.T_pose_lidar)),
          1e3 * std::abs(r.time_offset_s - o.time_offset_s)};
}

void print(const char* what, const LidarPoseResult& r, const Errors& e) {
  std::cout << what << ": error " << 100 * e.translation_m << " cm, " << e.rotation_deg << " deg, " << e.time_ms
            << " ms; " << r.points.size() << " points, evaluations " << r.global_evaluations << " + "
            << r.coarse_evaluations << " + " << r.local_evaluations - r.coarse_evaluations << " ("
            << r.global_status << ", " << r.coarse_status << ", " << r.local_status << "), time "
            << r.global_seconds << " + " << r.local_seconds << " s\n"
            << r.observability.text();
}

bool bitIdentical(const LidarPoseResult& a, const LidarPoseResult& b) {
  return std::memcmp(a.T_pose_lidar.matrix().data(), b.T_pose_lidar.matrix().data(), 16 * sizeof(double)) == 0 &&
         std::memcmp(&a.time_offset_s, &b.time_offset_s, sizeof(double)) == 0 &&
         std::memcmp(&a.final_cost, &b.final_cost, sizeof(double)) == 0 &&
         std::memcmp(&a.global_cost, &b.global_cost, sizeof(double)) == 0 &&
         a.local_evaluations == b.local_evaluations && a.global_evaluations == b.global_evaluations;
}

// 8 s of a rig shaken by ±15° roll and ±12° pitch while driving a figure of eight, lidar mounted at
// (0.5, −0.2, 0.3) m, (3°, −4°, 10°), 15 ms behind the pose clock, 3 mm range noise; 5 % of the returns
// (~51 000 points). z is the weakest parameter: it is seen only through the small sideways shift that
// tilting gives a lever arm along z, so it needs this much data (with 1 % it lands 2–5 cm off).
// Sanitizer builds check memory and threads, not accuracy: they use 1 % and loose tolerances.
test::SyntheticOptions accuracyOptions() {
  test::SyntheticOptions o;
  o.duration_s = 8.0;
  o.selection.keep_points_ratio = kSanitized ? 0.01 : 0.05;
  return o;
}

TEST(LidarPoseCalibration, RecoversExtrinsicAndTimeOffsetOnAShakenRig) {
  const test::SyntheticOptions o = accuracyOptions();
  const test::SyntheticRecording rec = test::makeSyntheticRecording(o);
  const PoseTrajectory traj(rec.pose_stamps, rec.poses);
  LidarPoseSettings s;  // lidar_align's defaults: global from identity, then local, 200 evaluations each
  s.selection = o.selection;
  const LidarPoseResult r = calibrateLidarPose(rec.scans, traj, s);
  const Errors e = errorsOf(r, o);
  print("synthetic", r, e);
  for (std::size_t i = 0; i < kLidarPoseParams; ++i)
    EXPECT_FALSE(r.observability.poorly_constrained[i] || r.held[i]) << i;
  const double scale = kSanitized ? 5.0 : 1.0;
  EXPECT_LT(e.translation_m, 0.02 * scale);
  EXPECT_LT(e.rotation_deg, 0.1 * scale);
  EXPECT_LT(e.time_ms, 1.0 * scale);
  EXPECT_LT(r.final_cost, r.initial_cost);
  EXPECT_EQ(r.points.counts.outside_poses, 0u);
  EXPECT_EQ(r.points.counts.kept, r.points.size());
  EXPECT_GT(r.points.size(), kSanitized ? 7000u : 45000u);
}

TEST(LidarPoseCalibration, RepeatedRunsAndThreadCountsGiveBitIdenticalResults) {
  test::SyntheticOptions o;  // small: identity, not accuracy, is the point here
  o.duration_s = 3.0;
  o.columns = 600;
  o.selection.keep_points_ratio = 0.05;
  const test::SyntheticRecording rec = test::makeSyntheticRecording(o);
  const PoseTrajectory traj(rec.pose_stamps, rec.poses);
  LidarPoseSettings s;
  s.selection = o.selection;
  s.threads = 2;
  const LidarPoseResult r = calibrateLidarPose(rec.scans, traj, s);
  EXPECT_GT(r.local_evaluations, 20u);
  EXPECT_TRUE(bitIdentical(r, calibrateLidarPose(rec.scans, traj, s))) << "a second run differs";
  s.threads = 1;
  EXPECT_TRUE(bitIdentical(r, calibrateLidarPose(rec.scans, traj, s))) << "1 thread differs from 2";
}

TEST(LidarPoseCalibration, PlanarMotionFlagsRollPitchAndZAndHoldsThemAtTheInitialGuess) {
  test::SyntheticOptions o;  // 10 s, lidar_align's 1 % subset
  if (kSanitized) o.duration_s = 6.0;
  o.planar = true;
  // Roll and pitch are 0 so that holding them at the (identity) guess is right; z is not, and stays 0.
  o.T_pose_lidar = fromXyzRpy({0.5, -0.2, 0.3, 0.0, 0.0, deg2rad(10.0)});
  const test::SyntheticRecording rec = test::makeSyntheticRecording(o);
  const PoseTrajectory traj(rec.pose_stamps, rec.poses);
  LidarPoseSettings s;
  s.selection = o.selection;
  const LidarPoseResult r = calibrateLidarPose(rec.scans, traj, s);
  const Errors e = errorsOf(r, o);
  print("planar", r, e);
  const auto& obs = r.observability;
  EXPECT_LT(obs.rotation_range_deg[0], 0.01);
  EXPECT_LT(obs.rotation_range_deg[1], 0.01);
  EXPECT_GT(obs.rotation_range_deg[2], 90.0);
  for (const LidarPoseParam p : {LidarPoseParam::kZ, LidarPoseParam::kRoll, LidarPoseParam::kPitch}) {
    EXPECT_TRUE(obs.flagged(p)) << lidarPoseParamName(p);
    EXPECT_TRUE(r.held[static_cast<std::size_t>(p)]);
    EXPECT_FALSE(obs.reason[static_cast<std::size_t>(p)].empty());
  }
  for (const LidarPoseParam p : {LidarPoseParam::kX, LidarPoseParam::kY, LidarPoseParam::kYaw,
                                 LidarPoseParam::kTimeOffset})
    EXPECT_FALSE(obs.flagged(p)) << lidarPoseParamName(p);
  EXPECT_NE(obs.text().find("poorly constrained: z (translation along z needs rotation about another axis"),
            std::string::npos)
      << obs.text();

  const XyzRpy got = toXyzRpy(r.T_pose_lidar);
  EXPECT_EQ(got.z, 0.0) << "held exactly at the initial guess";
  EXPECT_NEAR(got.roll, 0.0, 1e-12);
  EXPECT_NEAR(got.pitch, 0.0, 1e-12);
  // What the motion does determine is still recovered.
  const double scale = kSanitized ? 5.0 : 1.0;
  EXPECT_NEAR(got.x, 0.5, 0.02 * scale);
  EXPECT_NEAR(got.y, -0.2, 0.02 * scale);
  EXPECT_NEAR(rad2deg(got.yaw), 10.0, 0.1 * scale);
  EXPECT_LT(e.time_ms, 1.0 * scale);
}

TEST(LidarPoseObservability, ZNeedsAWideTiltRangeNotJustSomeTilt) {
  test::SyntheticOptions o;  // only the poses matter here
  o.duration_s = 8.0;
  o.columns = 20;
  o.roll_amplitude_deg = 5.0;
  o.pitch_amplitude_deg = 4.0;
  const test::SyntheticRecording mild = test::makeSyntheticRecording(o);
  const PoseTrajectory mild_traj(mild.pose_stamps, mild.poses);
  const ObservabilityReport m = assessObservability(mild_traj, mild_traj.begin(), mild_traj.end());
  std::cout << m.text();
  EXPECT_TRUE(m.flagged(LidarPoseParam::kZ));
  EXPECT_NE(m.reason[static_cast<std::size_t>(LidarPoseParam::kZ)].find("seen only through tilt"),
            std::string::npos);
  for (const LidarPoseParam p : {LidarPoseParam::kX, LidarPoseParam::kY, LidarPoseParam::kRoll,
                                 LidarPoseParam::kPitch, LidarPoseParam::kYaw, LidarPoseParam::kTimeOffset})
    EXPECT_FALSE(m.flagged(p)) << lidarPoseParamName(p);

  o.roll_amplitude_deg = 15.0;
  o.pitch_amplitude_deg = 12.0;
  const test::SyntheticRecording shaken = test::makeSyntheticRecording(o);
  const PoseTrajectory shaken_traj(shaken.pose_stamps, shaken.poses);
  EXPECT_FALSE(assessObservability(shaken_traj, shaken_traj.begin(), shaken_traj.end()).flagged(LidarPoseParam::kZ));
}

TEST(LidarPoseCalibration, AStationaryRecordingHoldsEveryParameterAtTheGuess) {
  test::SyntheticOptions o;
  o.duration_s = 1.0;
  o.columns = 200;
  o.selection.keep_points_ratio = 0.2;
  const test::SyntheticRecording rec = test::makeSyntheticRecording(o);
  const std::vector<Pose> still(rec.poses.size(), rec.poses.front());
  const PoseTrajectory traj(rec.pose_stamps, still);
  LidarPoseSettings s;
  s.selection = o.selection;
  s.initial_T_pose_lidar = fromXyzRpy({0.1, 0.2, 0.3, 0.01, 0.02, 0.03});
  s.initial_time_offset_s = 0.005;
  const LidarPoseResult r = calibrateLidarPose(rec.scans, traj, s);
  for (std::size_t i = 0; i < kLidarPoseParams; ++i) {
    EXPECT_TRUE(r.observability.poorly_constrained[i]) << i;
    EXPECT_TRUE(r.held[i]) << i;
  }
  EXPECT_TRUE(r.T_pose_lidar.isApprox(s.initial_T_pose_lidar, 1e-12));
  EXPECT_EQ(r.time_offset_s, 0.005);
  EXPECT_EQ(r.global_status, "skipped");
  EXPECT_EQ(r.local_status, "skipped");
  EXPECT_EQ(r.final_cost, r.initial_cost);
}

TEST(LidarPoseCalibration, PosesNotCoveringTheLidarTimeRangeAreAClearError) {
  test::SyntheticOptions o;
  o.duration_s = 1.0;
  o.columns = 100;
  const test::SyntheticRecording rec = test::makeSyntheticRecording(o);
  std::vector<TimeNs> later = rec.pose_stamps;
  for (auto& t : later) t += 100 * kNsPerSec;
  const PoseTrajectory traj(later, rec.poses);
  LidarPoseSettings s;
  s.selection = o.selection;
  try {
    calibrateLidarPose(rec.scans, traj, s);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("the poses do not cover the lidar time range: poses span [1700000099.500000000, "),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("lidar points span [1700000000.0"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace rigcal::calib
