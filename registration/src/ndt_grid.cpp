#include "rigcal/registration/ndt_grid.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "voxel_hash.hpp"

namespace rigcal::registration {

namespace {
constexpr std::uint32_t kNoCell = std::numeric_limits<std::uint32_t>::max();

struct Accumulator {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // first point: sums relative to it stay precise
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_sq = Eigen::Matrix3d::Zero();
  std::size_t count = 0;
  detail::VoxelCoord coord;
};
}  // namespace

NdtGrid::NdtGrid(const PointCloud& cloud, const NdtGridOptions& options) : options_(options) {
  if (!(std::isfinite(options.resolution) && options.resolution > 0.0)) {
    throw std::invalid_argument("NdtGrid: resolution must be finite and > 0, got " +
                                std::to_string(options.resolution));
  }
  inv_resolution_ = 1.0 / options.resolution;
  detail::VoxelIndexMap map(cloud.size() / 8 + 16);
  std::vector<Accumulator> acc;
  for (const auto& p : cloud.points) {
    detail::VoxelCoord c;
    if (!detail::voxelCoord(p, inv_resolution_, &c)) continue;
    const std::uint32_t v = map.findOrInsert(c);
    if (v == acc.size()) {
      acc.emplace_back();
      acc.back().origin = p.head<3>();
      acc.back().coord = c;
    }
    Accumulator& a = acc[v];
    const Eigen::Vector3d d = p.head<3>() - a.origin;
    a.sum += d;
    a.sum_sq.noalias() += d * d.transpose();
    ++a.count;
  }

  const std::size_t min_points = static_cast<std::size_t>(std::max(options.min_points_per_voxel, 3));
  std::vector<detail::VoxelCoord> coords;
  for (const Accumulator& a : acc) {
    if (a.count < min_points) continue;
    const double n = static_cast<double>(a.count);
    const Eigen::Vector3d mean_rel = a.sum / n;
    // Unbiased sample covariance, as PCL.
    Eigen::Matrix3d cov = (a.sum_sq - n * mean_rel * mean_rel.transpose()) / (n - 1.0);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(cov);
    Eigen::Vector3d values = eig.eigenvalues();
    const double floor_value = options.min_eigenvalue_ratio * values.maxCoeff();
    if (!(values.maxCoeff() > 0.0) || !std::isfinite(values.maxCoeff())) continue;  // all points identical
    values = values.cwiseMax(floor_value);
    const Eigen::Matrix3d& U = eig.eigenvectors();
    NdtCell cell;
    cell.mean.head<3>() = a.origin + mean_rel;
    cell.inverse_covariance.topLeftCorner<3, 3>() = U * values.cwiseInverse().asDiagonal() * U.transpose();
    cells_.push_back(cell);
    coords.push_back(a.coord);
  }

  std::size_t capacity = 16;
  while (capacity < 2 * cells_.size()) capacity *= 2;
  table_.assign(capacity, Slot{0, 0, 0, kNoCell});
  mask_ = capacity - 1;
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    std::size_t slot = detail::hashVoxel(coords[i]) & mask_;
    while (table_[slot].cell != kNoCell) slot = (slot + 1) & mask_;
    table_[slot] = {coords[i].x, coords[i].y, coords[i].z, static_cast<std::uint32_t>(i)};
  }
}

const NdtCell* NdtGrid::find(std::int64_t x, std::int64_t y, std::int64_t z) const {
  std::size_t slot = detail::hashVoxel({x, y, z}) & mask_;
  for (;;) {
    const Slot& s = table_[slot];
    if (s.cell == kNoCell) return nullptr;
    if (s.x == x && s.y == y && s.z == z) return &cells_[s.cell];
    slot = (slot + 1) & mask_;
  }
}

bool NdtGrid::voxelOf(const Eigen::Vector4d& p, Voxel* out) const {
  detail::VoxelCoord c;
  if (!detail::voxelCoord(p, inv_resolution_, &c)) return false;
  *out = {c.x, c.y, c.z};
  return true;
}

std::size_t NdtGrid::neighbors(const Eigen::Vector4d& p, NdtNeighborhood which, const NdtCell** out) const {
  Voxel v;
  if (cells_.empty() || !voxelOf(p, &v)) return 0;
  return neighbors(v, which, out);
}

std::size_t NdtGrid::neighbors(const Voxel& c, NdtNeighborhood which, const NdtCell** out) const {
  if (cells_.empty()) return 0;
  std::size_t n = 0;
  auto visit = [&](std::int64_t dx, std::int64_t dy, std::int64_t dz) {
    if (const NdtCell* cell = find(c.x + dx, c.y + dy, c.z + dz)) out[n++] = cell;
  };
  switch (which) {
    case NdtNeighborhood::kDirect1:
      visit(0, 0, 0);
      break;
    case NdtNeighborhood::kDirect7:
      visit(0, 0, 0);
      visit(-1, 0, 0);
      visit(1, 0, 0);
      visit(0, -1, 0);
      visit(0, 1, 0);
      visit(0, 0, -1);
      visit(0, 0, 1);
      break;
    case NdtNeighborhood::kDirect27:
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        for (std::int64_t dy = -1; dy <= 1; ++dy) {
          for (std::int64_t dz = -1; dz <= 1; ++dz) visit(dx, dy, dz);
        }
      }
      break;
  }
  return n;
}

}  // namespace rigcal::registration
