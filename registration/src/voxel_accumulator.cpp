#include "rigcal/registration/voxel_accumulator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "voxel_hash.hpp"

namespace rigcal::registration {

struct VoxelAccumulator::Impl {
  explicit Impl(std::size_t expected) : map(expected / 4 + 16) {}
  double inv_leaf = 1.0;
  detail::VoxelIndexMap map;
  // Sums relative to the voxel's first point (as voxelDownsample): full precision far from the origin.
  std::vector<Eigen::Vector4d> first;
  std::vector<Eigen::Vector4d> sum;  // w counts the points
};

VoxelAccumulator::VoxelAccumulator(double leaf_size, std::size_t expected_points) {
  if (!(std::isfinite(leaf_size) && leaf_size > 0.0)) {
    throw std::invalid_argument("VoxelAccumulator: leaf_size must be finite and > 0, got " + std::to_string(leaf_size));
  }
  impl_ = std::make_unique<Impl>(expected_points);
  impl_->inv_leaf = 1.0 / leaf_size;
}

VoxelAccumulator::~VoxelAccumulator() = default;

void VoxelAccumulator::add(std::span<const Eigen::Vector4d> points) {
  Impl& s = *impl_;
  added_ += points.size();
  for (const auto& p : points) {
    detail::VoxelCoord c;
    if (!p.head<3>().allFinite() || !detail::voxelCoord(p, s.inv_leaf, &c)) {
      ++dropped_;
      continue;
    }
    const std::uint32_t v = s.map.findOrInsert(c);
    if (v == s.first.size()) {
      s.first.push_back(p);
      s.sum.emplace_back(0.0, 0.0, 0.0, 0.0);
    }
    s.sum[v].head<3>() += (p - s.first[v]).head<3>();
    s.sum[v].w() += 1.0;
  }
}

std::size_t VoxelAccumulator::voxels() const { return impl_->first.size(); }

PointCloud VoxelAccumulator::centroids() const {
  const Impl& s = *impl_;
  PointCloud out;
  out.points.resize(s.first.size());
  for (std::size_t v = 0; v < s.first.size(); ++v) {
    out.points[v] = s.first[v] + s.sum[v] / s.sum[v].w();
    out.points[v].w() = 1.0;
  }
  return out;
}

}  // namespace rigcal::registration
