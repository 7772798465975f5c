#include "rigcal/registration/voxel_accumulator.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "voxel_hash.hpp"

namespace rigcal::registration {

namespace {

// A calibration target's accumulator holds a few hundred thousand voxels while the calibration's other
// targets are alive, so each voxel costs 56 bytes plus an 8-byte slot (two Vector4d and a 28-byte slot
// per voxel before, issue #18), and the voxels live in fixed chunks: no vector doubling that holds the old
// and the new array at once and leaves up to half of the new one unused.
struct Voxel {
  Eigen::Vector3d first;  // sums are relative to the voxel's first point (as voxelDownsample): full precision
  Eigen::Vector3d sum;    // far from the origin
  double count = 0.0;
};

// The slot keeps the hash's low 32 bits (its position is those bits & mask) and the voxel's index; the
// voxel's coordinates are recomputed from its first point (the same floor as when it was inserted) only
// when the hashes agree.
struct Slot {
  std::uint32_t hash = 0;
  std::uint32_t index = std::numeric_limits<std::uint32_t>::max();
};

constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();
constexpr std::size_t kChunkBits = 11;  // 2048 voxels, 112 KiB: below malloc's mmap threshold
constexpr std::size_t kChunkSize = std::size_t{1} << kChunkBits;

}  // namespace

struct VoxelAccumulator::Impl {
  explicit Impl(std::size_t expected) {
    std::size_t capacity = 16;
    while (capacity < 2 * (expected / 4 + 16)) capacity *= 2;
    slots.assign(capacity, Slot{});
  }

  Voxel& at(std::size_t v) { return chunks[v >> kChunkBits][v & (kChunkSize - 1)]; }
  [[nodiscard]] const Voxel& at(std::size_t v) const { return chunks[v >> kChunkBits][v & (kChunkSize - 1)]; }

  [[nodiscard]] bool holds(const Voxel& v, const detail::VoxelCoord& c) const {
    return static_cast<std::int64_t>(std::floor(v.first.x() * inv_leaf)) == c.x &&
           static_cast<std::int64_t>(std::floor(v.first.y() * inv_leaf)) == c.y &&
           static_cast<std::int64_t>(std::floor(v.first.z() * inv_leaf)) == c.z;
  }

  /// The voxel of c (which p falls in), appended with p as its first point when new.
  Voxel& findOrInsert(const detail::VoxelCoord& c, const Eigen::Vector4d& p) {
    if (2 * (count + 1) > slots.size()) grow();
    const auto hash = static_cast<std::uint32_t>(detail::hashVoxel(c));
    const std::size_t mask = slots.size() - 1;
    std::size_t s = hash & mask;
    while (slots[s].index != kEmpty) {
      if (slots[s].hash == hash && holds(at(slots[s].index), c)) return at(slots[s].index);
      s = (s + 1) & mask;
    }
    if ((count & (kChunkSize - 1)) == 0) chunks.push_back(std::make_unique<Voxel[]>(kChunkSize));
    slots[s] = {hash, static_cast<std::uint32_t>(count)};
    Voxel& v = at(count++);
    v.first = p.head<3>();
    v.sum.setZero();
    return v;
  }

  void grow() {
    std::vector<Slot> old(2 * slots.size());
    old.swap(slots);
    const std::size_t mask = slots.size() - 1;
    for (const Slot& o : old) {
      if (o.index == kEmpty) continue;
      std::size_t s = o.hash & mask;
      while (slots[s].index != kEmpty) s = (s + 1) & mask;
      slots[s] = o;
    }
  }

  double inv_leaf = 1.0;
  std::vector<Slot> slots;
  std::vector<std::unique_ptr<Voxel[]>> chunks;
  std::size_t count = 0;
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
    if (!detail::voxelCoord(p, s.inv_leaf, &c)) {
      ++dropped_;
      continue;
    }
    Voxel& v = s.findOrInsert(c, p);
    v.sum += p.head<3>() - v.first;
    v.count += 1.0;
  }
}

std::size_t VoxelAccumulator::voxels() const { return impl_->count; }

PointCloud VoxelAccumulator::centroids() const {
  const Impl& s = *impl_;
  PointCloud out;
  out.points.resize(s.count);
  for (std::size_t v = 0; v < s.count; ++v) {
    const Voxel& x = s.at(v);
    out.points[v].head<3>() = x.first + x.sum / x.count;
    out.points[v].w() = 1.0;
  }
  return out;
}

}  // namespace rigcal::registration
