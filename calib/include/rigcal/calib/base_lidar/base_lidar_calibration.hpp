#pragma once
// Base-lidar calibration: the ground seen by the mapping lidar gives z, roll and pitch of T_base_lidar;
// x, y and yaw are not observable from the ground and are kept from the initial guess.
#include <string>
#include <vector>

#include "rigcal/calib/base_lidar/ground_plane.hpp"
#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"

namespace rigcal::calib {

struct BaseLidarResult {
  bool ok = false;
  std::string failure;
  Pose T_base_lidar = Pose::Identity();
  GroundPlane plane;            // in the lidar frame
  std::size_t cropped_points = 0;
  /// Filled by calibrateBaseLidarMulti: ground fits tried and accepted, and the accepted estimates'
  /// median absolute deviation from the combined one (z in metres, roll and pitch in degrees).
  std::size_t keyframes_tried = 0;
  std::size_t keyframes_used = 0;
  double spread_z = 0.0, spread_roll_deg = 0.0, spread_pitch_deg = 0.0;
};

/// T_base_lidar from the ground plane. The plane gives the ground pose in the lidar frame (origin: the
/// lidar's foot on the ground). As upstream, the initial T_base_ground is projected onto the ground
/// (keeping that foot's x, y and the heading) and composed with it; overwrite_xy_yaw instead copies the
/// initial guess's own x, y, yaw.
Pose baseFromGround(const GroundPlane& plane, const Pose& initial_T_base_lidar, bool overwrite_xy_yaw);

/// Crops `points_lidar` to the base_lidar_crop_box (in base_link, under the initial guess), finds the
/// ground and returns T_base_lidar.
BaseLidarResult calibrateBaseLidar(const std::vector<Eigen::Vector3d>& points_lidar,
                                   const Pose& initial_T_base_lidar, const config::Parameters& params);

}  // namespace rigcal::calib
