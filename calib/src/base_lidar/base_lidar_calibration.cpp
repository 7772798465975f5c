#include "rigcal/calib/base_lidar/base_lidar_calibration.hpp"

#include <cmath>

namespace rigcal::calib {

namespace {
// The ground frame seen from the lidar: z = plane normal, origin = the lidar origin projected onto
// the plane, x = the lidar's x axis projected onto the plane.
Pose groundInLidar(const GroundPlane& plane) {
  const Eigen::Vector3d z = plane.normal;
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - z * z.x();
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitY() - z * z.y();
  x.normalize();
  Pose T = Pose::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = z.cross(x);
  T.linear().col(2) = z;
  T.translation() = -plane.d * z;  // the foot of the perpendicular from the lidar origin
  return T;
}
}  // namespace

Pose baseFromGround(const GroundPlane& plane, const Pose& initial_T_base_lidar, bool overwrite_xy_yaw) {
  const Pose T_lidar_ground = groundInLidar(plane);
  // Project the initial base→ground transform onto the ground: keep x, y, yaw only.
  const XyzRpy g = toXyzRpy(initial_T_base_lidar * T_lidar_ground);
  const Pose T_base_ground = fromXyzRpy({g.x, g.y, 0.0, 0.0, 0.0, g.yaw});
  Pose T_base_lidar = T_base_ground * T_lidar_ground.inverse();
  if (overwrite_xy_yaw) {
    XyzRpy r = toXyzRpy(T_base_lidar);
    const XyzRpy init = toXyzRpy(initial_T_base_lidar);
    r.x = init.x;
    r.y = init.y;
    r.yaw = init.yaw;
    T_base_lidar = fromXyzRpy(r);
  }
  return T_base_lidar;
}

BaseLidarResult calibrateBaseLidar(const std::vector<Eigen::Vector3d>& points_lidar,
                                   const Pose& initial_T_base_lidar, const config::Parameters& p) {
  BaseLidarResult result;
  const Eigen::Vector3d lo(p.base_lidar_crop_box_min_x, p.base_lidar_crop_box_min_y, p.base_lidar_crop_box_min_z);
  const Eigen::Vector3d hi(p.base_lidar_crop_box_max_x, p.base_lidar_crop_box_max_y, p.base_lidar_crop_box_max_z);
  std::vector<Eigen::Vector3d> cropped;
  cropped.reserve(points_lidar.size());
  for (const auto& q : points_lidar) {
    const Eigen::Vector3d b = initial_T_base_lidar * q;
    if ((b.array() >= lo.array()).all() && (b.array() <= hi.array()).all()) cropped.push_back(q);
  }
  result.cropped_points = cropped.size();

  GroundPlaneSettings s;
  s.max_inlier_distance = p.base_lidar_max_inlier_distance;
  s.max_iterations = p.base_lidar_max_iterations;
  s.min_plane_points = p.base_lidar_min_plane_points;
  s.min_plane_points_percentage = p.base_lidar_min_plane_points_percentage;
  s.max_cos_distance = p.base_lidar_max_cos_distance;
  const Eigen::Vector3d up = initial_T_base_lidar.linear().transpose() * Eigen::Vector3d::UnitZ();
  const GroundPlaneResult ground = findGroundPlane(cropped, up, s);
  if (!ground.plane) {
    result.failure = ground.failure + " (" + std::to_string(cropped.size()) + " points in the crop box)";
    return result;
  }
  result.plane = *ground.plane;
  result.T_base_lidar = baseFromGround(result.plane, initial_T_base_lidar, p.base_lidar_overwrite_xy_yaw);
  result.ok = true;
  return result;
}

}  // namespace rigcal::calib
