#pragma once
// The NDT target: one Gaussian (mean, inverse covariance) per occupied cubic voxel of side `resolution`,
// in a hash map keyed by full 64-bit voxel coordinates. Built like PCL's VoxelGridCovariance: voxels with
// fewer than min_points_per_voxel points are left out and small eigenvalues are raised to
// min_eigenvalue_ratio × the largest, so flat voxels stay invertible. Immutable once built.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::registration {

/// Which voxels a transformed source point is scored against.
enum class NdtNeighborhood {
  kDirect1,   // its own voxel
  kDirect7,   // its own and the 6 face neighbours (default: smooth enough, 7 hash lookups)
  kDirect27,  // the full 3x3x3 block
};

struct NdtGridOptions {
  double resolution = 1.0;           // m, upstream ndt_resolution
  int min_points_per_voxel = 6;      // PCL's default
  double min_eigenvalue_ratio = 0.01;
};

struct NdtCell {
  Eigen::Vector4d mean = Eigen::Vector4d::UnitW();  // w = 1, so mean and points subtract to w = 0
  Eigen::Matrix4d inverse_covariance = Eigen::Matrix4d::Zero();  // last row/column zero
};

class NdtGrid {
 public:
  NdtGrid() = default;
  /// Throws std::invalid_argument for a non-positive or non-finite resolution. Non-finite points are skipped.
  NdtGrid(const PointCloud& cloud, const NdtGridOptions& options);

  [[nodiscard]] double resolution() const { return options_.resolution; }
  [[nodiscard]] const NdtGridOptions& options() const { return options_; }
  [[nodiscard]] std::size_t size() const { return cells_.size(); }
  [[nodiscard]] bool empty() const { return cells_.empty(); }
  [[nodiscard]] const std::vector<NdtCell>& cells() const { return cells_; }

  /// Cells around p (at most 27 written to `out`); returns how many.
  std::size_t neighbors(const Eigen::Vector4d& p, NdtNeighborhood which, const NdtCell** out) const;

  /// The integer voxel of p; false for a point no voxel can hold (non-finite, absurdly far).
  struct Voxel {
    std::int64_t x = 0, y = 0, z = 0;
    friend bool operator==(const Voxel&, const Voxel&) = default;
  };
  bool voxelOf(const Eigen::Vector4d& p, Voxel* out) const;
  /// Cells around a voxel (at most 27 written to `out`); returns how many.
  std::size_t neighbors(const Voxel& v, NdtNeighborhood which, const NdtCell** out) const;

 private:
  struct Slot {
    std::int64_t x, y, z;
    std::uint32_t cell;  // kEmpty when the slot is free
  };
  [[nodiscard]] const NdtCell* find(std::int64_t x, std::int64_t y, std::int64_t z) const;

  NdtGridOptions options_;
  double inv_resolution_ = 1.0;
  std::vector<NdtCell> cells_;
  std::vector<Slot> table_;  // open addressing over cells_, only voxels that became cells
  std::size_t mask_ = 0;
};

}  // namespace rigcal::registration
