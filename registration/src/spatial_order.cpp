#include "spatial_order.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace rigcal::registration::detail {

namespace {
// Spreads the low 21 bits of v three apart (bit k moves to bit 3k).
std::uint64_t spreadBits(std::uint64_t v) {
  v &= 0x1FFFFFU;
  v = (v | v << 32U) & 0x1F00000000FFFFULL;
  v = (v | v << 16U) & 0x1F0000FF0000FFULL;
  v = (v | v << 8U) & 0x100F00F00F00F00FULL;
  v = (v | v << 4U) & 0x10C30C30C30C30C3ULL;
  v = (v | v << 2U) & 0x1249249249249249ULL;
  return v;
}
}  // namespace

std::vector<std::uint32_t> spatialOrder(std::span<const Eigen::Vector4d> points, double cell) {
  Eigen::Array3d lo = Eigen::Array3d::Constant(std::numeric_limits<double>::infinity());
  for (const auto& p : points) {
    if (p.head<3>().allFinite()) lo = lo.min(p.head<3>().array());
  }
  constexpr double kMaxCell = 0x1FFFFF;  // 21 bits an axis; a larger extent shares the last cell
  struct Keyed {
    std::uint64_t key;
    std::uint32_t index;
  };
  constexpr std::uint64_t kNotFinite = std::numeric_limits<std::uint64_t>::max();
  std::vector<Keyed> keyed(points.size());
  std::uint64_t last = 0;  // the largest finite key
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::uint64_t key = kNotFinite;
    if (points[i].head<3>().allFinite()) {
      const Eigen::Array3d c = ((points[i].head<3>().array() - lo) / cell).min(kMaxCell);
      key = spreadBits(static_cast<std::uint64_t>(c.x())) | spreadBits(static_cast<std::uint64_t>(c.y())) << 1U |
            spreadBits(static_cast<std::uint64_t>(c.z())) << 2U;
      last = std::max(last, key);
    }
    keyed[i] = {key, static_cast<std::uint32_t>(i)};
  }
  for (Keyed& k : keyed) k.key = std::min(k.key, last + 1);  // non-finite last, without widening the keys
  // LSD radix sort, a byte a pass over the bytes any key uses: stable, so ties keep the input order.
  const std::uint64_t used = last + 1;
  std::vector<Keyed> scratch(keyed.size());
  for (unsigned shift = 0; shift < 64 && (used >> shift) != 0; shift += 8) {
    std::array<std::size_t, 257> start{};
    for (const Keyed& k : keyed) ++start[((k.key >> shift) & 0xFFU) + 1];
    for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
    for (const Keyed& k : keyed) scratch[start[(k.key >> shift) & 0xFFU]++] = k;
    keyed.swap(scratch);
  }
  std::vector<std::uint32_t> order(points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = keyed[i].index;
  return order;
}

}  // namespace rigcal::registration::detail
