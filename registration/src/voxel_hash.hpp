#pragma once
// Private: integer voxel coordinates and an open-addressing map from them to dense indices, shared by the
// voxel filter and the NDT grid. Each axis keeps a full int64 coordinate (no packing), so neither a huge
// extent nor a tiny leaf can overflow the key.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

namespace rigcal::registration::detail {

struct VoxelCoord {
  std::int64_t x = 0, y = 0, z = 0;
  friend bool operator==(const VoxelCoord&, const VoxelCoord&) = default;
};

/// floor(p / leaf) per axis; false for a non-finite point or one beyond ±2^62 voxels from the origin. The one
/// rule of which points a voxel holds, for every voxel pass (voxelDownsample, VoxelAccumulator, the NDT grid,
/// VoxelOrderedCloud, whose merge is voxelDownsample's bit for bit only as long as they drop the same points).
inline bool voxelCoord(const Eigen::Vector4d& p, double inv_leaf, VoxelCoord* out) {
  constexpr double kLimit = 4.6e18;  // < 2^62, leaves room for ±1 neighbour offsets
  const double fx = std::floor(p.x() * inv_leaf);
  const double fy = std::floor(p.y() * inv_leaf);
  const double fz = std::floor(p.z() * inv_leaf);
  // Written so that NaN fails every comparison and is rejected.
  if (!(std::abs(fx) < kLimit && std::abs(fy) < kLimit && std::abs(fz) < kLimit)) return false;
  *out = {static_cast<std::int64_t>(fx), static_cast<std::int64_t>(fy), static_cast<std::int64_t>(fz)};
  return true;
}

inline std::uint64_t hashVoxel(const VoxelCoord& c) {
  // Large odd multipliers spread neighbouring voxels; the splitmix64 finaliser mixes the high bits down.
  std::uint64_t h = static_cast<std::uint64_t>(c.x) * 0x9E3779B97F4A7C15ULL ^
                    static_cast<std::uint64_t>(c.y) * 0xC2B2AE3D27D4EB4FULL ^
                    static_cast<std::uint64_t>(c.z) * 0x165667B19E3779F9ULL;
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ULL;
  h ^= h >> 27;
  return h;
}

/// VoxelCoord → dense index (0, 1, 2, ... in insertion order). Linear probing, grows at half load.
class VoxelIndexMap {
 public:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

  explicit VoxelIndexMap(std::size_t expected = 16) { rehash(capacityFor(expected)); }

  [[nodiscard]] std::size_t size() const { return size_; }

  /// The index of c, inserting it with index size() when absent.
  std::uint32_t findOrInsert(const VoxelCoord& c) {
    if (2 * (size_ + 1) > keys_.size()) rehash(keys_.size() * 2);
    std::size_t slot = hashVoxel(c) & mask_;
    while (values_[slot] != kNone) {
      if (keys_[slot] == c) return values_[slot];
      slot = (slot + 1) & mask_;
    }
    keys_[slot] = c;
    values_[slot] = static_cast<std::uint32_t>(size_);
    return static_cast<std::uint32_t>(size_++);
  }

  [[nodiscard]] std::uint32_t find(const VoxelCoord& c) const {
    std::size_t slot = hashVoxel(c) & mask_;
    while (values_[slot] != kNone) {
      if (keys_[slot] == c) return values_[slot];
      slot = (slot + 1) & mask_;
    }
    return kNone;
  }

 private:
  static std::size_t capacityFor(std::size_t expected) {
    std::size_t cap = 16;
    while (cap < 2 * expected) cap *= 2;
    return cap;
  }

  void rehash(std::size_t capacity) {
    std::vector<VoxelCoord> old_keys = std::move(keys_);
    std::vector<std::uint32_t> old_values = std::move(values_);
    keys_.assign(capacity, VoxelCoord{});
    values_.assign(capacity, kNone);
    mask_ = capacity - 1;
    for (std::size_t i = 0; i < old_keys.size(); ++i) {
      if (old_values[i] == kNone) continue;
      std::size_t slot = hashVoxel(old_keys[i]) & mask_;
      while (values_[slot] != kNone) slot = (slot + 1) & mask_;
      keys_[slot] = old_keys[i];
      values_[slot] = old_values[i];
    }
  }

  std::vector<VoxelCoord> keys_;
  std::vector<std::uint32_t> values_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace rigcal::registration::detail
