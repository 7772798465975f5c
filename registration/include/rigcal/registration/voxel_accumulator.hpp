#pragma once
// voxelDownsample fed in pieces: points are added batch by batch (one mapping cloud at a time) and the
// centroids taken at the end. The same voxels, order and arithmetic as voxelDownsample over the
// concatenation of the batches (bit-identical), without holding that concatenation, and a caller can stop
// between batches (a calibration deadline) instead of waiting for one pass over everything.
#include <cstddef>
#include <memory>
#include <span>

#include <Eigen/Core>

#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::registration {

class VoxelAccumulator {
 public:
  /// Throws std::invalid_argument unless leaf_size is finite and > 0. `expected_points` sizes the map.
  explicit VoxelAccumulator(double leaf_size, std::size_t expected_points = 0);
  ~VoxelAccumulator();
  VoxelAccumulator(const VoxelAccumulator&) = delete;
  VoxelAccumulator& operator=(const VoxelAccumulator&) = delete;

  /// Non-finite points and points beyond any voxel are dropped (counted), as in voxelDownsample.
  void add(std::span<const Eigen::Vector4d> points);
  [[nodiscard]] std::size_t added() const { return added_; }
  [[nodiscard]] std::size_t dropped() const { return dropped_; }
  [[nodiscard]] std::size_t voxels() const;
  /// The centroids, in the order their voxels were first hit.
  [[nodiscard]] PointCloud centroids() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::size_t added_ = 0, dropped_ = 0;
};

}  // namespace rigcal::registration
