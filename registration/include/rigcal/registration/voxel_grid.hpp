#pragma once
// Voxel downsampling: one point (the centroid) per occupied cube of side leaf_size.
// Voxels are keyed by a full 64-bit integer coordinate per axis in a hash map, so a large extent with a
// small leaf cannot overflow (PCL's VoxelGrid packs the three into one int and fails there).
#include <cstddef>

#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::registration {

struct VoxelGridStats {
  std::size_t input = 0;
  std::size_t output = 0;
  std::size_t dropped = 0;  // non-finite, or so far out (> 2^62 leaves) no voxel can hold them
};

/// Centroids in the order their voxels are first hit (deterministic). Normals and covariances are not
/// carried over. Throws std::invalid_argument unless leaf_size is finite and > 0.
PointCloud voxelDownsample(const PointCloud& cloud, double leaf_size, VoxelGridStats* stats = nullptr);

}  // namespace rigcal::registration
