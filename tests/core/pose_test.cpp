#include <gtest/gtest.h>

#include <random>

#include "rigcal/core/pose.hpp"

namespace rigcal {
namespace {

Pose randomPose(std::mt19937& rng, double max_angle = M_PI) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Vector3d axis(u(rng), u(rng), u(rng));
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(max_angle * std::abs(u(rng)), axis.normalized()).toRotationMatrix();
  T.translation() = 10.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
  return T;
}

bool near(const Pose& a, const Pose& b, double tol) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff() < tol;
}

TEST(Pose, XyzRpyRoundTripAndConvention) {
  const XyzRpy v{1.0, -2.0, 0.5, 0.1, -0.2, 2.5};
  const XyzRpy w = toXyzRpy(fromXyzRpy(v));
  EXPECT_NEAR(w.x, v.x, 1e-12);
  EXPECT_NEAR(w.roll, v.roll, 1e-12);
  EXPECT_NEAR(w.pitch, v.pitch, 1e-12);
  EXPECT_NEAR(w.yaw, v.yaw, 1e-12);
  // A pure yaw of +90° turns x forward into y left.
  const Pose yaw90 = fromXyzRpy({0, 0, 0, 0, 0, M_PI / 2});
  EXPECT_TRUE((yaw90.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
}

TEST(Pose, RpyAtGimbalLockStillReproducesRotation) {
  const Pose T = fromXyzRpy({0, 0, 0, 0.3, M_PI / 2, 0.2});
  EXPECT_TRUE(near(fromXyzRpy(toXyzRpy(T)), T, 1e-9));
}

TEST(Pose, Se3ExpLogAreInverse) {
  std::mt19937 rng(7);
  for (int i = 0; i < 200; ++i) {
    const Pose T = randomPose(rng, 3.1);
    EXPECT_TRUE(near(expSE3(logSE3(T)), T, 1e-9)) << "sample " << i;
  }
  // Tiny rotations take the series branch.
  Vector6d xi;
  xi << 0.5, -0.2, 0.1, 1e-9, -2e-9, 1e-9;
  EXPECT_TRUE(logSE3(expSE3(xi)).isApprox(xi, 1e-9));
}

TEST(Pose, So3LogNearPiStaysInRange) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI - 1e-9, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d w = logSO3(R);
  EXPECT_NEAR(w.norm(), M_PI, 1e-6);
  EXPECT_TRUE(expSO3(w).isApprox(R, 1e-9));
}

TEST(Pose, InterpolationEndpointsAndMidpoint) {
  std::mt19937 rng(3);
  const Pose a = randomPose(rng, 1.0), b = randomPose(rng, 1.0);
  EXPECT_TRUE(near(interpolateLerpSlerp(a, b, 0.0), a, 1e-12));
  EXPECT_TRUE(near(interpolateLerpSlerp(a, b, 1.0), b, 1e-12));
  EXPECT_TRUE(near(interpolateGeodesic(a, b, 0.0), a, 1e-9));
  EXPECT_TRUE(near(interpolateGeodesic(a, b, 1.0), b, 1e-9));
  const Pose mid = interpolateLerpSlerp(a, b, 0.5);
  EXPECT_TRUE(mid.translation().isApprox(0.5 * (a.translation() + b.translation()), 1e-12));
  EXPECT_NEAR(rotationAngleBetween(a, mid), rotationAngleBetween(mid, b), 1e-9);
}

TEST(Pose, InterpolateAtUsesTimes) {
  const Pose a = Pose::Identity();
  Pose b = Pose::Identity();
  b.translation() = Eigen::Vector3d(4, 0, 0);
  const Pose p = interpolateAt(100, a, 500, b, 200);
  EXPECT_NEAR(p.translation().x(), 1.0, 1e-12);
}

TEST(Pose, GeodesicFollowsConstantScrewMotion) {
  // Constant yaw rate and forward speed: the geodesic midpoint lies on the arc, not the chord.
  const Pose b = fromXyzRpy({std::sin(1.0), 1.0 - std::cos(1.0), 0, 0, 0, 1.0});
  const Pose mid = interpolateGeodesic(Pose::Identity(), b, 0.5);
  EXPECT_NEAR(mid.translation().x(), std::sin(0.5), 1e-9);
  EXPECT_NEAR(mid.translation().y(), 1.0 - std::cos(0.5), 1e-9);
}

}  // namespace
}  // namespace rigcal
