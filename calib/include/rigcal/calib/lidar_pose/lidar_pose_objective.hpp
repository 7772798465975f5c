#pragma once
// lidar_align's objective: fuse every selected return into one cloud in the world frame under a
// candidate extrinsic T_pose_lidar and time offset,
//   p_world = T_world_pose(t_lidar + time_offset) · T_pose_lidar · p_lidar,
// and sum over the points min(d²_NN, max_dist_sq), d_NN the distance to the nearest *other* point.
//
// How it differs from lidar_align (which copies the cloud into a PCL cloud, rebuilds a kd-tree and
// copies cloud and tree again for every batch of 1000 queries): only neighbours closer than
// r = sqrt(max_dist_sq) change the sum, so the cloud is radix-sorted by (z cell, y cell, fine x) with
// cells of size r. Each (y, z) column is then one run ordered by x; a query visits its own and the 8
// neighbouring columns (found by cursors that only move forward), skips a column whose y/z gap already
// exceeds the best distance, and scans outwards in x until |Δx| alone does. Each query starts from the
// distance to its previous nearest neighbour (warm start). All buffers are allocated
// once; poses are re-interpolated only when the time offset changes; the work is split over 1..n
// threads and reduced in a fixed order, so the result is bit-identical for any thread count and run.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rigcal/calib/lidar_pose/lidar_pose_points.hpp"
#include "rigcal/calib/lidar_pose/pose_trajectory.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/worker_pool.hpp"

namespace rigcal::calib {

class LidarPoseObjective {
 public:
  /// `points` and `trajectory` must outlive the objective. Every point must have a pose at
  /// t ± the largest time offset evaluated (restrictToTrajectory guarantees it). threads ≥ 1.
  LidarPoseObjective(const LidarPoints& points, const PoseTrajectory& trajectory, int threads = 2);
  ~LidarPoseObjective();
  LidarPoseObjective(const LidarPoseObjective&) = delete;
  LidarPoseObjective& operator=(const LidarPoseObjective&) = delete;

  /// Σ_i min(d²_NN(i), max_dist_sq) in square metres. Not reentrant. Throws std::out_of_range when a
  /// point's time + time_offset_s has no pose.
  double evaluate(const Pose& T_pose_lidar, double time_offset_s, double max_dist_sq);

  /// The fused cloud of the last evaluate(), world frame, in the order of `points`.
  [[nodiscard]] const std::vector<float>& fusedX() const { return wx_; }
  [[nodiscard]] const std::vector<float>& fusedY() const { return wy_; }
  [[nodiscard]] const std::vector<float>& fusedZ() const { return wz_; }

  [[nodiscard]] std::size_t size() const { return n_; }
  [[nodiscard]] int threads() const { return threads_; }
  [[nodiscard]] std::size_t evaluations() const { return evaluations_; }

 private:
  /// fn(part) for each of the threads_ parts of the points, on the pool (each part's outputs are its own).
  template <class Fn>
  void forEachPart(const Fn& fn) {
    workers_.parallelFor(static_cast<std::size_t>(threads_),
                         [&](std::size_t part) { fn(static_cast<int>(part)); });
  }
  void updatePoses(double time_offset_s);
  void transform(int part, const Pose& T_pose_lidar);
  void sortByCell();
  void sweep(int part);
  [[nodiscard]] std::pair<std::size_t, std::size_t> pointRange(int part) const;

  const LidarPoints& points_;
  const PoseTrajectory& trajectory_;
  std::size_t n_;
  int threads_;
  WorkerPool workers_;
  std::size_t evaluations_ = 0;

  // T_world_pose(t_i + offset) per point, row-major R then t; valid for `pose_offset_`.
  std::vector<double> pose_cache_;
  double pose_offset_ = 0.0;
  bool poses_valid_ = false;
  std::vector<std::uint8_t> pose_missing_;  // per part

  // Fused cloud (input order) and its cell coordinates.
  std::vector<float> wx_, wy_, wz_;
  std::vector<float> part_min_, part_max_;  // per part: bounding box (x, y, z)
  float max_sq_ = 1.0f;
  float inv_cell_ = 1.0f, cell_ = 1.0f;        // y, z cells: a fraction of the neighbour radius
  float inv_quantum_ = 1.0f, quantum_ = 1.0f;  // x quantum: a 256th of the radius
  std::int64_t origin_[3] = {0, 0, 0};  // lowest x quantum / y, z cell, minus a margin
  std::uint64_t nx_ = 0, nxy_ = 0;      // x quanta per column, quanta per z layer

  // Radix-sorted (cell key, point) pairs and the cloud gathered in that order.
  std::vector<std::uint64_t> keys_, keys_tmp_;
  std::vector<std::uint32_t> order_, order_tmp_;
  struct SortedPoint {  // what a query and a neighbour test read, in one 32-byte record
    std::uint64_t key;
    float x, y, z;
    float fy, fz;      // position inside its y, z cell, in [0, 1)
    std::uint32_t qx;  // x quantum (the low part of key)
  };
  std::vector<SortedPoint> sorted_;
  std::vector<std::size_t> sweep_split_;  // part p sweeps sorted positions [split[p], split[p+1])
  std::vector<float> cost_;               // per sorted position
  // Per point (input order): its nearest neighbour at the previous evaluation, or kNoPartner. The
  // optimiser moves the cloud little between evaluations, so the distance to that point, measured at
  // the new positions, starts the search with a tight bound and prunes most candidates. It is a real
  // distance to another point, so the minimum found — and the sum — are exactly what a cold search gives.
  static constexpr std::uint32_t kNoPartner = 0xffffffffu;
  std::vector<std::uint32_t> partner_;
};

}  // namespace rigcal::calib
