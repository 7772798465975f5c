#pragma once
// The global stage before a cloud pair's ensemble: finds the right basin from a guess up to ~1 m and
// ~60° off, where ICP/NDT/GICP alone converge to a wrong one.
//   1. The ground plane of each cloud (RANSAC, ground_plane.hpp) fixes roll, pitch and height: the source
//      ground's normal is turned onto the target's (the smallest turn from the guess) and the source origin
//      is put at the height the two ground distances give.
//   2. A coarse search over yaw about the ground normal and translation along the ground, on voxelised
//      clouds, scored by the ensemble's inlier-aware score (mean of min(d², d_max²), calibration_score.hpp)
//      read from a truncated distance grid of the target (one lookup per point instead of a tree search).
//   3. The best few basins (apart by ≥ basin_separation) are refined on a finer grid; the best is the start
//      of the ensemble and the second-best's score says how unique it is.
// Own code on Eigen; deterministic (no random sampling beyond the seeded RANSAC).
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"

namespace rigcal::calib {

struct GlobalSearchSettings {
  // ± about the (levelled) guess; 180 = the full turn, so a side lidar whose guess is 60° off (or a
  // mount with no guess at all) still lands in its basin. The full turn costs 2.4× the ±75° it replaced.
  double yaw_range_deg = 180.0;
  double yaw_step_deg = 3.0;
  double translation_range = 1.4;     // ± m along the ground, about the guess
  double translation_step = 0.2;
  double voxel = 0.25;                // source and target voxel for the search (m)
  double max_distance = 0.5;          // d_max of the score (m): wider than the ensemble's, for coarse steps
  std::size_t max_source_points = 1000;
  double max_source_range = 30.0;     // m: farther points move too much between yaw steps to score
  double basin_separation_m = 0.5;    // two results closer than this and basin_separation_deg are one basin
  double basin_separation_deg = 10.0;
  std::size_t basins_refined = 4;
  double ground_inlier_distance = 0.08;  // RANSAC inlier band (m): lidar ground is rough at range
};

struct GlobalSearchResult {
  Pose T_target_source = Pose::Identity();  // the best basin's refined pose
  bool ground_used = false;                 // both ground planes found: roll, pitch and height from them
  std::string ground_note;                  // why not, when not
  double best_score = 0.0;                  // m², the search's score (lower is better)
  double best_inlier_ratio = 0.0;
  std::optional<double> second_score;       // the second-best basin's score; none when there is one basin
  std::optional<Pose> second_T_target_source;
  std::size_t poses_scored = 0;
  double seconds = 0.0;
};

/// `target` and `source` are the clouds in their own frames, `guess` the user's T_target_source.
GlobalSearchResult globalSearch(const std::vector<Eigen::Vector3d>& target, const std::vector<Eigen::Vector3d>& source,
                                const Pose& guess, const GlobalSearchSettings& settings = {});

}  // namespace rigcal::calib
