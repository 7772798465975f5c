#pragma once
// A cloud stored in the order of its points' voxels, so that the voxel pass over a concatenation of such
// clouds is a merge of sorted runs instead of a hash insert per point. The mapper's local map is such a
// pass: its last 15 keyframes, again at every keyframe (a VLS-128 local map at 0.1 m is ~1 M points hashed
// into a voxel map of ~10 MB: a cache miss a point). The merge gives voxelDownsample's output bit for bit
// (the same centroids, summed in the same order, listed in the same order), so nothing downstream can tell
// the two apart.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::registration {

class VoxelOrderedCloud {
 public:
  /// The cloud's positions (w ignored, as voxelDownsample does). Throws std::invalid_argument unless leaf is
  /// finite and > 0, or with 2^32 points or more.
  VoxelOrderedCloud(const PointCloud& cloud, double leaf);

  [[nodiscard]] double leaf() const { return leaf_; }
  /// The points a voxel holds (non-finite ones and those beyond any voxel left out), by voxel and, within
  /// one, in the cloud's order; and where each was in the cloud. Stored in this order, so that a merge reads
  /// them front to back.
  [[nodiscard]] const std::vector<Eigen::Vector3d>& byVoxel() const { return points_; }
  [[nodiscard]] const std::vector<std::uint32_t>& placeInCloud() const { return place_; }
  /// The points given, dropped ones included.
  [[nodiscard]] std::size_t cloudSize() const { return cloud_size_; }

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::uint32_t> place_;
  std::size_t cloud_size_;
  double leaf_;
};

/// voxelDownsample(concatenation of the clouds' points, leaf), bit for bit: the same centroids in the same
/// order (the order their voxels are first hit along the concatenation). Every cloud must have this leaf.
/// Throws std::invalid_argument otherwise.
PointCloud voxelDownsampleConcatenation(std::span<const VoxelOrderedCloud* const> clouds, double leaf);

}  // namespace rigcal::registration
