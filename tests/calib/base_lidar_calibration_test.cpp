#include <gtest/gtest.h>

#include <random>

#include "rigcal/calib/base_lidar/base_lidar_calibration.hpp"

namespace rigcal::calib {
namespace {

// Upstream's ±20 m crop box: these scenes spread the ground over ±15 m (and put a wall 5 m ahead), wider
// than the default vehicle footprint.
config::Parameters wideBox() {
  config::Parameters p;
  p.base_lidar_crop_box_min_x = p.base_lidar_crop_box_min_y = p.base_lidar_crop_box_min_z = -20.0;
  p.base_lidar_crop_box_max_x = p.base_lidar_crop_box_max_y = p.base_lidar_crop_box_max_z = 20.0;
  return p;
}

// Points in the lidar frame of a scene in base_link: a ground plane (z = 0) with 2 mm noise, an
// optional large wall, and clutter. `truth` is T_base_lidar.
std::vector<Eigen::Vector3d> scene(const Pose& truth, bool big_wall, bool ground = true) {
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::uniform_real_distribution<double> u(-15.0, 15.0);
  std::vector<Eigen::Vector3d> base;
  if (ground)
    for (int i = 0; i < 20000; ++i) base.emplace_back(u(rng), u(rng), noise(rng));
  if (big_wall)  // 30 m × 6 m wall 5 m ahead, denser than the ground
    for (int i = 0; i < 30000; ++i) base.emplace_back(5.0 + noise(rng), u(rng), 3.0 + 0.2 * u(rng));
  for (int i = 0; i < 3000; ++i) base.emplace_back(u(rng), u(rng), 0.5 + std::abs(u(rng)) / 5);
  const Pose T_lidar_base = truth.inverse();
  for (auto& p : base) p = T_lidar_base * p;
  return base;
}

void expectMatchesTruth(const BaseLidarResult& r, const Pose& truth, const Pose& initial) {
  ASSERT_TRUE(r.ok) << r.failure;
  const XyzRpy got = toXyzRpy(r.T_base_lidar), want = toXyzRpy(truth), init = toXyzRpy(initial);
  EXPECT_NEAR(got.z, want.z, 0.01);
  EXPECT_NEAR(rad2deg(got.roll), rad2deg(want.roll), 0.05);
  EXPECT_NEAR(rad2deg(got.pitch), rad2deg(want.pitch), 0.05);
  // x, y, yaw are not observable from the ground. As upstream, the initial guess's ground pose is kept:
  // the lidar's foot on the ground (x, y) and its heading.
  const Eigen::Vector3d foot_lidar = -r.plane.d * r.plane.normal;
  EXPECT_TRUE((r.T_base_lidar * foot_lidar).head<2>().isApprox((initial * foot_lidar).head<2>(), 1e-9));
  const auto heading = [](const Pose& T) {
    const Eigen::Vector3d x = T.linear().col(0);
    return std::atan2(x.y(), x.x());
  };
  EXPECT_NEAR(heading(r.T_base_lidar), heading(initial), deg2rad(0.5));
  EXPECT_NEAR(got.yaw, init.yaw, deg2rad(0.5));
}

TEST(BaseLidarCalibration, RecoversHeightRollPitchFromAPerturbedGuess) {
  const Pose truth = fromXyzRpy({1.2, 0.1, 1.85, deg2rad(2.0), deg2rad(-3.0), deg2rad(30.0)});
  const Pose initial = fromXyzRpy({1.25, 0.05, 2.15, deg2rad(-3.0), deg2rad(2.0), deg2rad(32.0)});
  const BaseLidarResult r = calibrateBaseLidar(scene(truth, false), initial, wideBox());
  expectMatchesTruth(r, truth, initial);
  EXPECT_EQ(r.plane.attempts, 1);
  EXPECT_GT(r.plane.normal.dot(initial.linear().transpose() * Eigen::Vector3d::UnitZ()), 0.99);
}

TEST(BaseLidarCalibration, RejectsADominantWallThenFindsTheGround) {
  const Pose truth = fromXyzRpy({0, 0, 1.5, deg2rad(1.0), deg2rad(1.0), 0});
  const Pose initial = fromXyzRpy({0, 0, 1.7, 0, 0, 0});
  const BaseLidarResult r = calibrateBaseLidar(scene(truth, true), initial, wideBox());
  expectMatchesTruth(r, truth, initial);
  EXPECT_GE(r.plane.attempts, 2) << "the wall is found first and rejected by its normal";
}

TEST(BaseLidarCalibration, NormalIsOrientedUpForAnUpsideDownLidar) {
  const Pose truth = fromXyzRpy({0, 0, 2.0, M_PI - deg2rad(1.0), deg2rad(0.5), deg2rad(10)});
  const Pose initial = fromXyzRpy({0, 0, 2.2, M_PI, 0, deg2rad(10)});
  const BaseLidarResult r = calibrateBaseLidar(scene(truth, false), initial, wideBox());
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_NEAR(r.T_base_lidar.translation().z(), 2.0, 0.01);
  EXPECT_LT(rotationAngleBetween(r.T_base_lidar, truth), deg2rad(0.05));
}

TEST(BaseLidarCalibration, OverwriteXyYawCopiesTheInitialGuess) {
  const Pose truth = fromXyzRpy({1.0, 0.0, 1.8, 0.01, 0.02, 0.3});
  const Pose initial = fromXyzRpy({1.3, -0.2, 1.6, 0.0, 0.0, 0.25});
  config::Parameters p = wideBox();
  p.base_lidar_overwrite_xy_yaw = true;
  const BaseLidarResult r = calibrateBaseLidar(scene(truth, false), initial, p);
  ASSERT_TRUE(r.ok);
  const XyzRpy got = toXyzRpy(r.T_base_lidar);
  EXPECT_DOUBLE_EQ(got.x, 1.3);
  EXPECT_DOUBLE_EQ(got.y, -0.2);
  EXPECT_NEAR(got.yaw, 0.25, 1e-12);
  EXPECT_NEAR(got.z, 1.8, 0.01);
}

TEST(BaseLidarCalibration, NoGroundIsAClearFailure) {
  const Pose truth = fromXyzRpy({0, 0, 1.5, 0, 0, 0});
  const BaseLidarResult r = calibrateBaseLidar(scene(truth, false, false), truth, wideBox());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("no ground plane"), std::string::npos) << r.failure;
  EXPECT_EQ(r.failure.find('\n'), std::string::npos);
  EXPECT_FALSE(calibrateBaseLidar({}, truth, wideBox()).ok);
}

TEST(BaseLidarCalibration, SameInputSameResult) {
  const Pose truth = fromXyzRpy({0, 0, 1.5, 0.02, -0.01, 0});
  const auto points = scene(truth, true);
  const BaseLidarResult a = calibrateBaseLidar(points, Pose::Identity(), wideBox());
  const BaseLidarResult b = calibrateBaseLidar(points, Pose::Identity(), wideBox());
  ASSERT_TRUE(a.ok);
  EXPECT_TRUE(a.T_base_lidar.matrix() == b.T_base_lidar.matrix());
}

}  // namespace
}  // namespace rigcal::calib
