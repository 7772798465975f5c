#pragma once
// The lidar returns that take part in lidar-to-pose calibration: lidar_align's per-scan filters
// (keep ratio, intensity, range, finite) applied to decoded scans, each point keeping the absolute time
// its decoder gave it (stamp_ns + offset_ns), then restricted to the pose trajectory's time range.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rigcal/calib/lidar_pose/pose_trajectory.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/core/time.hpp"

namespace rigcal::calib {

/// lidar_align's Scan::Config, same names and defaults (estimate_point_times is not offered: every
/// decoder gives real per-point times).
struct LidarPointSelection {
  double keep_points_ratio = 0.01;
  double min_return_intensity = -1.0;  // kept when intensity > this
  double min_point_distance = 0.0;     // kept when min < range < max (metres)
  double max_point_distance = 100.0;
  /// Salt of the keep hash. Point i of a scan is kept when hash(seed, scan.sequence, i) falls below
  /// keep_points_ratio: the subset depends on neither run, thread count nor the order scans arrive in.
  std::uint64_t seed = 0;
};

struct LidarPointCounts {
  std::size_t scans = 0;
  std::size_t input = 0;          // every return of every scan
  std::size_t not_sampled = 0;    // dropped by keep_points_ratio
  std::size_t low_intensity = 0;  // intensity <= min_return_intensity
  std::size_t out_of_range = 0;   // non-finite, or range outside (min, max)
  std::size_t outside_poses = 0;  // time (± the largest time offset) outside the pose trajectory
  std::size_t kept = 0;
};

/// Selected returns as structure-of-arrays, in scan then point order. Coordinates in the lidar frame.
struct LidarPoints {
  std::vector<float> x, y, z, intensity;
  std::vector<TimeNs> time_ns;  // absolute lidar time of each point
  LidarPointCounts counts;

  [[nodiscard]] std::size_t size() const { return x.size(); }
  [[nodiscard]] bool empty() const { return x.empty(); }
};

/// The keep decision: a 64-bit mix of (seed, sequence, index) compared with ratio·2^64.
bool keepPoint(std::uint64_t seed, std::uint64_t sequence, std::size_t index, double ratio);

LidarPoints selectLidarPoints(const std::vector<Scan>& scans, const LidarPointSelection& selection);
/// Selects one scan's returns into `out` (and its counts): a decoder's scans can be consumed as they
/// arrive instead of being held (30 s of a VLP-16 is ~9 M returns; 1 % of them are kept).
void appendLidarPoints(const Scan& scan, const LidarPointSelection& selection, LidarPoints& out);

/// Drops (and counts in outside_poses) every point whose time t has no pose at t − margin_s or
/// t + margin_s, so that any time offset within ±margin_s finds a pose for every remaining point:
/// poses are interpolated, never extrapolated. Throws std::runtime_error naming both time ranges
/// when fewer than `min_points` remain.
void restrictToTrajectory(LidarPoints& points, const PoseTrajectory& trajectory, double margin_s,
                          std::size_t min_points = 2);

}  // namespace rigcal::calib
