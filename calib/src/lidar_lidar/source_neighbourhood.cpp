#include "rigcal/calib/lidar_lidar/source_neighbourhood.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace rigcal::calib {
namespace {
/// 21 bits per axis: ±1M cells, ±1000 km at 1 m cells; farther (or non-finite) points have no cell.
constexpr std::int64_t kAxisLimit = (std::int64_t{1} << 20) - 2;
constexpr std::uint64_t kNoCell = std::numeric_limits<std::uint64_t>::max();
}  // namespace

SourceNeighbourhood::SourceNeighbourhood(const registration::PointCloud& source, const std::vector<Pose>& poses,
                                         double radius) {
  if (!(radius > 0.0) || !std::isfinite(radius)) throw std::invalid_argument("SourceNeighbourhood: radius must be positive");
  inv_cell_ = 1.0 / radius;
  std::unordered_set<std::uint64_t> occupied;
  std::vector<Eigen::Vector3d> seeds;
  for (const Pose& T : poses) {
    for (const auto& p : source.points) {
      const Eigen::Vector3d q = T * p.head<3>();
      const std::uint64_t k = key(q);
      if (k != kNoCell && occupied.insert(k).second) seeds.push_back((q * inv_cell_).array().floor());
    }
  }
  cells_.reserve(occupied.size() * 8);
  for (const auto& c : seeds)
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          cells_.insert(pack(std::int64_t(c.x()) + dx, std::int64_t(c.y()) + dy, std::int64_t(c.z()) + dz));
}

std::uint64_t SourceNeighbourhood::pack(std::int64_t x, std::int64_t y, std::int64_t z) {
  const auto axis = [](std::int64_t v) { return std::uint64_t(v + (std::int64_t{1} << 20)) & 0x1FFFFF; };
  return axis(x) | (axis(y) << 21) | (axis(z) << 42);
}

std::uint64_t SourceNeighbourhood::key(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d c = (p * inv_cell_).array().floor();
  if (!c.allFinite() || (c.array().abs() > double(kAxisLimit)).any()) return kNoCell;
  return pack(std::int64_t(c.x()), std::int64_t(c.y()), std::int64_t(c.z()));
}

}  // namespace rigcal::calib
