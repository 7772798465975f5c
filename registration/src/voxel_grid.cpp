#include "rigcal/registration/voxel_grid.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "voxel_hash.hpp"

namespace rigcal::registration {

PointCloud voxelDownsample(const PointCloud& cloud, double leaf_size, VoxelGridStats* stats) {
  if (!(std::isfinite(leaf_size) && leaf_size > 0.0)) {
    throw std::invalid_argument("voxelDownsample: leaf_size must be finite and > 0, got " +
                                std::to_string(leaf_size));
  }
  const double inv_leaf = 1.0 / leaf_size;
  detail::VoxelIndexMap map(cloud.size() / 4 + 16);
  // Sums relative to the voxel's first point: keeps full precision far from the origin.
  std::vector<Eigen::Vector4d> first;
  std::vector<Eigen::Vector4d> sum;  // w counts the points
  std::size_t dropped = 0;
  for (const auto& p : cloud.points) {
    detail::VoxelCoord c;
    if (!detail::voxelCoord(p, inv_leaf, &c)) {
      ++dropped;
      continue;
    }
    const std::uint32_t v = map.findOrInsert(c);
    if (v == first.size()) {
      first.push_back(p);
      sum.emplace_back(0.0, 0.0, 0.0, 0.0);
    }
    sum[v].head<3>() += (p - first[v]).head<3>();
    sum[v].w() += 1.0;
  }
  PointCloud out;
  out.points.resize(first.size());
  for (std::size_t v = 0; v < first.size(); ++v) {
    out.points[v] = first[v] + sum[v] / sum[v].w();
    out.points[v].w() = 1.0;
  }
  if (stats) *stats = {cloud.size(), out.size(), dropped};
  return out;
}

}  // namespace rigcal::registration
