#include "rigcal/calib/lidar_lidar/source_neighbourhood.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace rigcal::calib {
namespace {
/// Beyond this many cells in the box the cells are kept in a hash set (a bit each would take 8 MB).
constexpr double kMaxBitmapCells = double(std::uint64_t{1} << 26);
/// Cells beyond ±2^20 per axis (±600 km at the default 0.6 m) are not kept: no real point lies there, and the
/// cells' numbers within their box stay below 2^64.
constexpr double kAxisLimit = double((std::int64_t{1} << 20) - 2);
}  // namespace

SourceNeighbourhood::SourceNeighbourhood(const registration::PointCloud& source, const std::vector<Pose>& poses,
                                         double radius) {
  if (!(radius > 0.0) || !std::isfinite(radius)) throw std::invalid_argument("SourceNeighbourhood: radius must be positive");
  inv_cell_ = 1.0 / radius;
  std::vector<Eigen::Array3d> seeds;  // the cells holding a placed source point
  Eigen::Array3d lo = Eigen::Array3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Pose& T : poses) {
    for (const auto& p : source.points) {
      const Eigen::Array3d c = ((T * p.head<3>()) * inv_cell_).array().floor();
      if (!(c.abs() < kAxisLimit).all()) continue;  // also drops NaN
      seeds.push_back(c);
      lo = lo.min(c);
      hi = hi.max(c);
    }
  }
  if (seeds.empty()) return;  // size_ 0: contains() is false everywhere
  origin_ = lo - 1.0;  // the 26 neighbours of the outermost cells too
  size_ = hi - lo + 3.0;
  const bool bitmap = size_.prod() <= kMaxBitmapCells;
  if (bitmap) bits_.assign(std::size_t(std::ceil(size_.prod() / 64.0)), 0);
  for (const auto& seed : seeds) {
    const Eigen::Array3d c = seed - origin_;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const std::uint64_t i = (std::uint64_t(c.x() + dx) * std::uint64_t(size_.y()) + std::uint64_t(c.y() + dy)) *
                                      std::uint64_t(size_.z()) + std::uint64_t(c.z() + dz);
          if (bitmap) {
            const std::uint64_t bit = std::uint64_t{1} << (i & 63);
            if ((bits_[i >> 6] & bit) == 0) ++cell_count_;
            bits_[i >> 6] |= bit;
          } else if (cells_.insert(i).second) {
            ++cell_count_;
          }
        }
  }
}

}  // namespace rigcal::calib
