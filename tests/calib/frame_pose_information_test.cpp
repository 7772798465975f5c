// A frame's information about the extrinsic (frame_pose_information.hpp), on real targets: it must be in the
// calibration lidar's own frame, since the verdict weights that frame's deviation (result⁻¹ · frame result,
// also in the lidar's frame) by it.
#include <gtest/gtest.h>

#include "rigcal/calib/lidar_lidar/frame_pose_information.hpp"

namespace rigcal::calib {
namespace {

/// A 10 m x 10 m patch of the ground (z = 0 in the mapping frame), every 10 cm.
registration::PointCloud ground() {
  registration::PointCloud c;
  for (int i = -50; i <= 50; ++i)
    for (int j = -50; j <= 50; ++j) c.add(0.1 * i, 0.1 * j, 0.0);
  return c;
}

registration::Target groundTarget() {
  registration::TargetOptions o;
  o.normals_and_covariances = true;
  return registration::Target(ground(), o);
}

// Seen by a lidar rolled 90° (its spin axis sideways, as yard-side's side_left): the ground's normal is the
// lidar's y axis, so the ground says everything about the lidar's y and nothing about its x or z.
TEST(FramePoseInformation, IsInTheCalibrationLidarsOwnFrame) {
  const registration::Target target = groundTarget();
  Pose T_mapping_lidar = Pose::Identity();
  T_mapping_lidar.translate(Eigen::Vector3d(0, 0, 1.5));
  T_mapping_lidar.rotate(Eigen::AngleAxisd(deg2rad(90.0), Eigen::Vector3d::UnitX()));
  // The ground's points in the lidar's frame.
  registration::PointCloud source;
  for (const auto& p : ground().points) {
    const Eigen::Vector3d q = T_mapping_lidar.inverse() * Eigen::Vector3d(p.head<3>());
    source.add(q.x(), q.y(), q.z());
  }
  const PoseInformation H = framePoseInformation(target, source, T_mapping_lidar, 0.1);
  const double n = H(1, 1);
  EXPECT_GT(n, 0.9 * double(source.size())) << "every point constrains the lidar's y";
  EXPECT_LT(H(0, 0), 1e-6 * n);
  EXPECT_LT(H(2, 2), 1e-6 * n);
  // Rotations about the lidar's x and z tilt the ground plane (in the mapping frame: roll and pitch); about
  // its y (the ground's normal) they slide the plane along itself.
  EXPECT_GT(H(3, 3), 0.1 * n);
  EXPECT_GT(H(5, 5), 0.1 * n);
  EXPECT_LT(H(4, 4), 1e-6 * n);
}

TEST(FramePoseInformation, NothingWithinReachIsNoInformation) {
  const registration::Target target = groundTarget();
  registration::PointCloud source;
  source.add(0, 0, 5);
  source.add(1, 0, 5);
  EXPECT_TRUE(framePoseInformation(target, source, Pose::Identity(), 0.1).isZero());
}

}  // namespace
}  // namespace rigcal::calib
