#pragma once
// Point-set comparison for reference decodes: how many points of one cloud have a point of the other
// within a tolerance (order free). A hash grid with cells of the tolerance's size; 27 cells per query.
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace rigcal::test {

using Xyz = std::array<float, 3>;

class PointGrid {
 public:
  PointGrid(const std::vector<Xyz>& points, double cell) : points_(points), cell_(cell) {
    for (std::size_t i = 0; i < points.size(); ++i) cells_[key(cellOf(points[i]))].push_back(i);
  }

  /// Whether some point lies within `tolerance` (≤ the cell size) of q.
  [[nodiscard]] bool hasNeighbour(const Xyz& q, double tolerance) const {
    const auto c = cellOf(q);
    const double t2 = tolerance * tolerance;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (std::size_t i : it->second) {
            const double ex = double(points_[i][0]) - q[0], ey = double(points_[i][1]) - q[1],
                         ez = double(points_[i][2]) - q[2];
            if (ex * ex + ey * ey + ez * ez <= t2) return true;
          }
        }
    return false;
  }

 private:
  [[nodiscard]] std::array<std::int64_t, 3> cellOf(const Xyz& p) const {
    return {std::int64_t(std::floor(p[0] / cell_)), std::int64_t(std::floor(p[1] / cell_)),
            std::int64_t(std::floor(p[2] / cell_))};
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    return (std::uint64_t(c[0] & 0x1FFFFF) << 42) | (std::uint64_t(c[1] & 0x1FFFFF) << 21) |
           std::uint64_t(c[2] & 0x1FFFFF);
  }
  const std::vector<Xyz>& points_;
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

/// Points of `a` with a point of `b` within `tolerance` metres.
inline std::size_t countMatched(const std::vector<Xyz>& a, const std::vector<Xyz>& b, double tolerance) {
  const PointGrid grid(b, tolerance);
  std::size_t n = 0;
  for (const Xyz& p : a) n += grid.hasNeighbour(p, tolerance) ? 1 : 0;
  return n;
}

}  // namespace rigcal::test
