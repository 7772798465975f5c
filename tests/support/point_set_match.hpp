#pragma once
// Point sets compared as sets (order free), as the vendors' reference decodes are: how many points of one
// have a point of the other within a tolerance, on a hashed grid of cells that size.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "rigcal/core/scan.hpp"

namespace rigcal::test {

struct Xyz {
  double x, y, z;
};

/// How many of `query` have a point of `cloud` within `tolerance` metres.
inline std::size_t countMatched(const std::vector<Xyz>& cloud, const std::vector<Xyz>& query, double tolerance) {
  auto cell = [&](double v) { return static_cast<std::int64_t>(std::floor(v / tolerance)); };
  auto key = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<std::uint64_t>((i * 73856093) ^ (j * 19349663) ^ (k * 83492791));
  };
  std::unordered_multimap<std::uint64_t, std::size_t> grid;
  grid.reserve(cloud.size() * 2);
  for (std::size_t n = 0; n < cloud.size(); ++n)
    grid.emplace(key(cell(cloud[n].x), cell(cloud[n].y), cell(cloud[n].z)), n);
  std::size_t matched = 0;
  for (const Xyz& q : query) {
    bool found = false;
    const std::int64_t ci = cell(q.x), cj = cell(q.y), ck = cell(q.z);
    for (std::int64_t di = -1; di <= 1 && !found; ++di)
      for (std::int64_t dj = -1; dj <= 1 && !found; ++dj)
        for (std::int64_t dk = -1; dk <= 1 && !found; ++dk) {
          auto [a, b] = grid.equal_range(key(ci + di, cj + dj, ck + dk));
          for (auto it = a; it != b && !found; ++it) {
            const Xyz& p = cloud[it->second];
            const double dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
            found = dx * dx + dy * dy + dz * dz <= tolerance * tolerance;
          }
        }
    matched += found;
  }
  return matched;
}

inline std::vector<Xyz> xyzOf(const Scan& scan) {
  std::vector<Xyz> v(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) v[i] = {scan.x[i], scan.y[i], scan.z[i]};
  return v;
}

}  // namespace rigcal::test
