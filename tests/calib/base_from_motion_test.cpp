// base_link yaw and x from the drive (calib::estimateBaseFromMotion) on analytic trajectories: a car
// whose rear axle (base_link's origin) moves along its x axis at speed v(t) with steering curvature κ(t),
// the mapping lidar mounted at T_base_lidar (x 1.2 m ahead of the axle, tilted, 2 m up) sampled at 10 Hz.
// The guess is 0.3 m and 5° off in x and yaw (z, roll, pitch right: the ground's part).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

#include "rigcal/calib/base_lidar/base_from_motion.hpp"

namespace rigcal::calib {
namespace {

struct DriveStep {
  double duration_s;
  double speed_mps;   // signed: negative = reversing
  double curvature;   // 1/m of the steering (positive = steer left)
};

struct Drive {
  std::vector<TimeNs> stamps;
  std::vector<Pose> T_map_lidar;
};

struct DriveNoise {
  double position_m = 0.0;      // σ per axis of the mapper's position
  double rotation_deg = 0.0;    // σ per axis of a small rotation
  double slip_per_g = 0.0;      // side-slip angle (rad) per g of lateral acceleration, toward the outside
  unsigned seed = 7;
};

const XyzRpy kTruth{1.2, 0.15, 2.0, deg2rad(1.5), deg2rad(-4.0), deg2rad(2.0)};

Pose guessOf(const XyzRpy& truth) {
  XyzRpy g = truth;
  g.x += 0.3;
  g.yaw += deg2rad(5.0);
  return fromXyzRpy(g);
}

/// Integrates the steps at 1 ms (speeds blended over 0.5 s so the motion is smooth), samples at 10 Hz.
Drive drive(const std::vector<DriveStep>& steps, const DriveNoise& noise = {}, const XyzRpy& truth = kTruth) {
  const Pose T_base_lidar = fromXyzRpy(truth);
  std::mt19937 rng(noise.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Drive d;
  double x = 0, y = 0, h = 0.3, v = 0, t = 0;
  const double dt = 1e-3;
  std::size_t tick = 0;
  for (const DriveStep& s : steps) {
    for (double u = 0; u < s.duration_s; u += dt, t += dt, ++tick) {
      v += (s.speed_mps - v) * std::min(1.0, dt / 0.15);
      // Side slip: the body's velocity points off its x axis, toward the outside of the turn.
      const double beta = -noise.slip_per_g * v * v * s.curvature / 9.81;
      x += v * std::cos(h + beta) * dt;
      y += v * std::sin(h + beta) * dt;
      h += v * s.curvature * dt;
      if (tick % 100 != 0) continue;
      Pose T_world_base = fromXyzRpy({x, y, 0, 0, 0, h});
      Pose T = T_world_base * T_base_lidar;
      if (noise.position_m > 0 || noise.rotation_deg > 0) {
        const Eigen::Vector3d dp(gauss(rng), gauss(rng), gauss(rng));
        const Eigen::Vector3d dr(gauss(rng), gauss(rng), gauss(rng));
        T.translation() += noise.position_m * dp;
        T.linear() = T.linear() * expSO3(deg2rad(noise.rotation_deg) * dr);
      }
      d.stamps.push_back(fromSeconds(t));
      d.T_map_lidar.push_back(T);
    }
  }
  return d;
}

BaseFromMotionResult estimate(const Drive& d, BaseFromMotionMode mode = BaseFromMotionMode::kYawX,
                              const XyzRpy& truth = kTruth) {
  return estimateBaseFromMotion(d.stamps, d.T_map_lidar, {}, guessOf(truth), mode);
}

// A radius-8 m arc turning `deg` degrees at 2 m/s (positive = left).
DriveStep arc(double deg, double speed = 2.0) {
  const double radius = 8.0;
  return {std::abs(deg2rad(deg)) * radius / std::abs(speed), speed, (deg > 0 ? 1.0 : -1.0) / radius};
}

void expectExact(const BaseFromMotionResult& r, bool x_too) {
  ASSERT_TRUE(r.yaw.estimated) << r.yaw.note;
  EXPECT_NEAR(rad2deg(r.yaw.value), rad2deg(kTruth.yaw), 0.01);
  EXPECT_EQ(r.x.estimated, x_too) << r.x.note;
  if (x_too) EXPECT_NEAR(r.x.value, kTruth.x, 0.005);
  else EXPECT_NEAR(r.x.value, kTruth.x + 0.3, 1e-12);  // the guess, untouched
  // z, roll, pitch and y stay as given.
  const XyzRpy out = toXyzRpy(r.T_base_lidar);
  EXPECT_NEAR(out.y, kTruth.y, 1e-12);
  EXPECT_NEAR(out.z, kTruth.z, 1e-12);
  EXPECT_NEAR(out.roll, kTruth.roll, 1e-9);
  EXPECT_NEAR(out.pitch, kTruth.pitch, 1e-9);
}

TEST(BaseFromMotion, StraightLineGivesYawAndSaysXIsNotObservable) {
  const auto r = estimate(drive({{2, 0, 0}, {12, 3.0, 0}}));
  expectExact(r, false);
  EXPECT_GT(r.straight_m, 25.0);
  EXPECT_EQ(r.left_turn_deg + r.right_turn_deg, 0.0);
  EXPECT_NE(r.x.note.find("not observable"), std::string::npos) << r.x.note;
  EXPECT_NE(r.x.note.find("kept the guess"), std::string::npos) << r.x.note;
  EXPECT_NE(describeBaseFromMotion(r).find("y from the guess"), std::string::npos);
}

TEST(BaseFromMotion, CircleOneWayIsNotEnough) {
  // A full circle turns one way only: x trades with yaw and there is no straight driving for yaw alone.
  const auto r = estimate(drive({arc(360)}));
  EXPECT_FALSE(r.yaw.estimated);
  EXPECT_FALSE(r.x.estimated);
  EXPECT_GT(r.left_turn_deg, 300.0);
  EXPECT_EQ(r.right_turn_deg, 0.0);
  EXPECT_NE(r.yaw.note.find("not observable"), std::string::npos) << r.yaw.note;
  EXPECT_NE(r.x.note.find("0 deg right"), std::string::npos) << r.x.note;
  const XyzRpy out = toXyzRpy(r.T_base_lidar);
  EXPECT_NEAR(out.x, kTruth.x + 0.3, 1e-12);
  EXPECT_NEAR(out.yaw, kTruth.yaw + deg2rad(5.0), 1e-12);
}

TEST(BaseFromMotion, FigureEightGivesYawAndX) {
  const auto r = estimate(drive({arc(360), arc(-360)}));
  expectExact(r, true);
  EXPECT_GT(r.left_turn_deg, 300.0);
  EXPECT_GT(r.right_turn_deg, 300.0);
  EXPECT_LT(r.x.stddev, 1e-3);
}

TEST(BaseFromMotion, YawModeLeavesXAlone) {
  const auto r = estimate(drive({{10, 3.0, 0}, arc(90), arc(-90)}), BaseFromMotionMode::kYaw);
  expectExact(r, false);
  EXPECT_NE(r.x.note.find("not estimated"), std::string::npos) << r.x.note;
}

TEST(BaseFromMotion, OffKeepsTheGuess) {
  const auto r = estimate(drive({{10, 3.0, 0}, arc(90), arc(-90)}), BaseFromMotionMode::kOff);
  EXPECT_FALSE(r.yaw.estimated);
  EXPECT_FALSE(r.x.estimated);
  EXPECT_TRUE(r.T_base_lidar.isApprox(guessOf(kTruth)));
}

TEST(BaseFromMotion, ReversingAndStops) {
  // Forward, stop, reverse through turns both ways (steering left while reversing still bends the path
  // as a left steer does), creep at 0.2 m/s (below the threshold), stop, forward again.
  const auto r = estimate(drive({{3, 2.0, 0}, {3, 0, 0}, arc(60, -1.5), {2, 0, 0}, arc(-60, -1.5), {6, 0.2, 0},
                                 {2, 0, 0}, {6, 2.5, 0}, {2, 0, 0}}));
  expectExact(r, true);
  EXPECT_GT(r.reversing_m, 10.0);
  EXPECT_GT(r.left_turn_deg, 40.0);
  EXPECT_GT(r.right_turn_deg, 40.0);
  // The creeping and the stops are not in the measurements.
  EXPECT_LT(r.moving_m, 3 * 2.0 + 2 * deg2rad(60) * 8.0 + 6 * 2.5 + 1.0);
}

TEST(BaseFromMotion, NoisyMapperAndOutliers) {
  // A mapper with 3 mm / 0.05° noise per pose and a few jumps of 0.3 m (a bad registration).
  auto d = drive({{8, 3.0, 0}, arc(120), {4, 3.0, 0}, arc(-120), {8, 3.0, 0}}, {0.003, 0.05, 0.0, 11});
  for (std::size_t k = 40; k < d.T_map_lidar.size(); k += 57) d.T_map_lidar[k].translation().y() += 0.3;
  const auto r = estimate(d);
  ASSERT_TRUE(r.yaw.estimated);
  ASSERT_TRUE(r.x.estimated);
  const double yaw_err = rad2deg(r.yaw.value - kTruth.yaw), x_err = r.x.value - kTruth.x;
  std::printf("noise 3 mm / 0.05 deg + jumps: yaw error %.4f deg (std %.4f), x error %.4f m (std %.4f), "
              "%zu of %zu chords, %zu outliers\n",
              yaw_err, rad2deg(r.yaw.stddev), x_err, r.x.stddev, r.chords_used, r.chords, r.outliers);
  EXPECT_LT(std::abs(yaw_err), 0.1);
  EXPECT_LT(std::abs(x_err), 0.05);
  EXPECT_GT(r.outliers, 0U);
  // The standard deviation is that of the data: the error lies within a few of them.
  EXPECT_GT(r.yaw.stddev, 0.0);
  EXPECT_LT(std::abs(yaw_err), 5 * rad2deg(r.yaw.stddev) + 0.01);
  EXPECT_LT(std::abs(x_err), 5 * r.x.stddev + 0.005);
}

TEST(BaseFromMotion, LostFramesBreakChords) {
  const auto clean = drive({{8, 3.0, 0}, arc(90), arc(-90)});
  auto d = clean;
  std::vector<bool> usable(d.stamps.size(), true);
  // A lost stretch whose poses are garbage: no chord may span it, so nothing changes but the chords lost.
  for (std::size_t k = 50; k < 60; ++k) {
    usable[k] = false;
    d.T_map_lidar[k].translation().x() += 5.0;
  }
  const auto r = estimateBaseFromMotion(d.stamps, d.T_map_lidar, usable, guessOf(kTruth), BaseFromMotionMode::kYawX);
  expectExact(r, true);
  const auto all = estimateBaseFromMotion(clean.stamps, clean.T_map_lidar, {}, guessOf(kTruth), BaseFromMotionMode::kYawX);
  EXPECT_LT(r.chords, all.chords);
  EXPECT_LE(r.outliers, all.outliers);
  EXPECT_LT(r.residual_rms_m, 1e-3);
}

TEST(BaseFromMotion, RejectsMismatchedInput) {
  const auto d = drive({{3, 2.0, 0}});
  std::vector<TimeNs> stamps(d.stamps.begin(), d.stamps.end() - 1);
  EXPECT_THROW(estimateBaseFromMotion(stamps, d.T_map_lidar, {}, guessOf(kTruth), BaseFromMotionMode::kYawX),
               std::invalid_argument);
  EXPECT_THROW(parseBaseFromMotionMode("xy"), std::invalid_argument);
  EXPECT_EQ(parseBaseFromMotionMode("yaw_x"), BaseFromMotionMode::kYawX);
}

// The limits, measured: side slip (a real tyre's slip angle grows with lateral acceleration) biases x,
// and mapper noise scatters both. Prints the numbers for the report; asserts only the direction of the
// slip bias: the rear slides out in a turn, so the point without lateral motion moves forward of the axle
// and the lidar seems nearer to it, by slip·v²/g (5°/g at 4 m/s: 14 cm).
TEST(BaseFromMotion, SideSlipAndNoiseLimits) {
  const std::vector<DriveStep> steps{{6, 4.0, 0}, arc(90, 4.0), {3, 4.0, 0}, arc(-90, 4.0), {6, 4.0, 0}};
  double previous_x_err = 1.0;
  for (double slip_deg_per_g : {0.0, 2.0, 5.0}) {
    const auto r = estimate(drive(steps, {0.0, 0.0, deg2rad(slip_deg_per_g), 3}));
    const double x_err = r.x.value - kTruth.x;
    std::printf("side slip %.0f deg/g at 4 m/s on 8 m arcs (0.2 g): yaw error %.4f deg, x error %+.3f m\n",
                slip_deg_per_g, rad2deg(r.yaw.value - kTruth.yaw), x_err);
    EXPECT_LT(x_err, previous_x_err + 1e-6);
    previous_x_err = x_err;
  }
  for (double pos_mm : {2.0, 5.0, 10.0}) {
    const auto r = estimate(drive(steps, {pos_mm * 1e-3, 0.05, 0.0, 5}));
    std::printf("mapper noise %.0f mm / 0.05 deg per pose: yaw error %.4f deg (std %.4f), x error %+.4f m (std %.4f)\n",
                pos_mm, rad2deg(r.yaw.value - kTruth.yaw), rad2deg(r.yaw.stddev), r.x.value - kTruth.x, r.x.stddev);
  }
}

}  // namespace
}  // namespace rigcal::calib

namespace rigcal::calib {
namespace {

TEST(BaseFromMotion, LongStopStaysCheap) {
  // Ten minutes parked (mapper jitter only) between two drives: skipped quickly, the drives still count.
  const auto r = [] {
    const auto d = drive({{6, 3.0, 0}, {600, 0, 0}, {6, 3.0, 0}}, {0.001, 0.01, 0.0, 9});
    return estimate(d, BaseFromMotionMode::kYaw);
  }();
  ASSERT_TRUE(r.yaw.estimated) << r.yaw.note;
  EXPECT_LT(std::abs(rad2deg(r.yaw.value - kTruth.yaw)), 0.1);
  EXPECT_LT(r.moving_m, 40.0);
}

}  // namespace
}  // namespace rigcal::calib
