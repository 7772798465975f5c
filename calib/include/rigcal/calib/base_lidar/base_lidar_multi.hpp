#pragma once
// Base-lidar calibration over many keyframes. On bumpy ground the body's attitude relative to the local
// ground plane changes with what lies under the wheels, so one keyframe's plane is off by that tilt; the
// lidar's mounting is the same at every keyframe. Fitting the ground at keyframes spread along the path
// and taking the median of the estimates cancels the terrain's part.
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "rigcal/calib/base_lidar/base_lidar_calibration.hpp"
#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"

namespace rigcal::calib {

struct BaseLidarMultiSettings {
  std::size_t max_keyframes = 24;        // keyframes fitted, spread evenly along the path
  std::size_t max_points_per_fit = 80000;  // the crop is thinned by a stride beyond this (RANSAC cost)
};

/// Fits the ground (calibrateBaseLidar) at each pose of `T_map_lidar_keyframes` on `map_points` (map
/// frame) brought into that keyframe's lidar frame, and combines the accepted estimates by their
/// per-component median. The result's multi_keyframe fields tell how many fits were tried and used and
/// their spread; it fails only when no keyframe gave a plane.
BaseLidarResult calibrateBaseLidarMulti(const std::vector<Eigen::Vector3d>& map_points,
                                        const std::vector<Pose>& T_map_lidar_keyframes,
                                        const Pose& initial_T_base_lidar, const config::Parameters& params,
                                        const BaseLidarMultiSettings& settings = {});

}  // namespace rigcal::calib
