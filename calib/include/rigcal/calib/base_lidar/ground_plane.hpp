#pragma once
// RANSAC ground-plane extraction with the upstream acceptance rules: a plane is accepted when it has
// enough inliers, a large enough share of the points, and a normal close to the expected "up".
// Otherwise its inliers are removed (a wall, a car roof) and the search repeats.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace rigcal::calib {

struct GroundPlaneSettings {
  double max_inlier_distance = 0.01;   // base_lidar_max_inlier_distance
  int max_iterations = 1000;           // base_lidar_max_iterations (per attempt)
  int min_plane_points = 1000;         // base_lidar_min_plane_points
  double min_plane_points_percentage = 10.0;  // base_lidar_min_plane_points_percentage
  double max_cos_distance = 0.5;       // base_lidar_max_cos_distance: 1 − |n·n_expected|
  int max_attempts = 10;               // planes tried before giving up
  std::uint64_t seed = 1;              // RANSAC sampling is seeded: same input, same plane
};

struct GroundPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, oriented along n_expected ("up")
  double d = 0.0;                                     // plane: normal·p + d = 0
  std::size_t inliers = 0;
  double inlier_percentage = 0.0;
  int attempts = 0;
};

struct GroundPlaneResult {
  std::optional<GroundPlane> plane;
  std::string failure;  // why no plane was accepted (one line)
};

/// `up` is the expected upward direction in the points' frame (unit).
GroundPlaneResult findGroundPlane(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up,
                                  const GroundPlaneSettings& settings);

}  // namespace rigcal::calib
