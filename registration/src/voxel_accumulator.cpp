#include "rigcal/registration/voxel_accumulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "rigcal/registration/parallel.hpp"
#include "voxel_hash.hpp"

namespace rigcal::registration {

namespace {

// A calibration target's accumulator holds a few hundred thousand voxels while the calibration's other
// targets are alive, so each voxel costs 56 bytes plus an 8-byte slot (two Vector4d and a 28-byte slot
// per voxel before, issue #18), and the voxels live in fixed chunks: no vector doubling that holds the old
// and the new array at once and leaves up to half of the new one unused.
// No initialisers: every field is set when its voxel is inserted, and chunks allocated ahead stay untouched
// (not resident) until used.
struct Voxel {
  Eigen::Vector3d first;  // sums are relative to the voxel's first point (as voxelDownsample): full precision
  Eigen::Vector3d sum;    // far from the origin
  std::uint32_t count;
  std::uint32_t order;  // the index of its first point among all added: the centroids' order
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

// The voxels are split by the hash's top bits into shards that threads fill independently: each voxel
// lives in one shard and gets its points in the order they were added, so its sum is the same sequence of
// additions whatever the thread count. The count is fixed (never the thread count's): results depend only
// on the input.
constexpr unsigned kShardBits = 2;
constexpr std::size_t kShards = std::size_t{1} << kShardBits;

std::size_t shardOf(std::uint64_t hash) { return static_cast<std::size_t>(hash >> (64 - kShardBits)); }

class Shard {
 public:
  /// The table and the voxel chunks for `expected_voxels` are allocated here, on the caller's thread: a shard
  /// filled on a helper thread allocates only beyond them (glibc gives a helper thread its own arena, where
  /// what it allocated and freed stays resident).
  explicit Shard(std::size_t expected_voxels) {
    std::size_t capacity = 16;
    while (capacity < 2 * expected_voxels) capacity *= 2;
    slots_.assign(capacity, Slot{});
    chunks_.reserve(chunkCount(expected_voxels, kChunkSize) + 16);
    for (std::size_t c = 0; c < chunkCount(expected_voxels, kChunkSize); ++c) chunks_.push_back(newChunk());
  }

  [[nodiscard]] std::size_t size() const { return count_; }
  [[nodiscard]] const Voxel& at(std::size_t v) const { return chunks_[v >> kChunkBits][v & (kChunkSize - 1)]; }

  void add(const detail::VoxelCoord& c, std::uint32_t hash, const Eigen::Vector4d& p, std::uint32_t order,
           double inv_leaf) {
    Voxel& v = findOrInsert(c, hash, p, order, inv_leaf);
    v.sum += p.head<3>() - v.first;
    ++v.count;
  }

 private:
  Voxel& at(std::size_t v) { return chunks_[v >> kChunkBits][v & (kChunkSize - 1)]; }

  static bool holds(const Voxel& v, const detail::VoxelCoord& c, double inv_leaf) {
    return static_cast<std::int64_t>(std::floor(v.first.x() * inv_leaf)) == c.x &&
           static_cast<std::int64_t>(std::floor(v.first.y() * inv_leaf)) == c.y &&
           static_cast<std::int64_t>(std::floor(v.first.z() * inv_leaf)) == c.z;
  }

  /// The voxel of c (which p falls in), appended with p as its first point when new.
  Voxel& findOrInsert(const detail::VoxelCoord& c, std::uint32_t hash, const Eigen::Vector4d& p,
                      std::uint32_t order, double inv_leaf) {
    if (2 * (count_ + 1) > slots_.size()) grow();
    const std::size_t mask = slots_.size() - 1;
    std::size_t s = hash & mask;
    while (slots_[s].index != kEmpty) {
      if (slots_[s].hash == hash && holds(at(slots_[s].index), c, inv_leaf)) return at(slots_[s].index);
      s = (s + 1) & mask;
    }
    if (count_ == chunks_.size() * kChunkSize) chunks_.push_back(newChunk());
    slots_[s] = {hash, static_cast<std::uint32_t>(count_)};
    Voxel& v = at(count_++);
    v.first = p.head<3>();
    v.sum.setZero();
    v.count = 0;
    v.order = order;
    return v;
  }

  static std::unique_ptr<Voxel[]> newChunk() { return std::make_unique_for_overwrite<Voxel[]>(kChunkSize); }

  void grow() {
    std::vector<Slot> old(2 * slots_.size());
    old.swap(slots_);
    const std::size_t mask = slots_.size() - 1;
    for (const Slot& o : old) {
      if (o.index == kEmpty) continue;
      std::size_t s = o.hash & mask;
      while (slots_[s].index != kEmpty) s = (s + 1) & mask;
      slots_[s] = o;
    }
  }

  std::vector<Slot> slots_;
  std::vector<std::unique_ptr<Voxel[]>> chunks_;
  std::size_t count_ = 0;
};

}  // namespace

struct VoxelAccumulator::Impl {
  explicit Impl(std::size_t expected_points) {
    for (std::size_t s = 0; s < kShards; ++s) shards.emplace_back((expected_points / 4 + 16) / kShards);
  }
  double inv_leaf = 1.0;
  std::vector<Shard> shards;
  std::vector<std::uint32_t> hash;  // scratch of add(): each point's hash (low bits) and shard
  std::vector<std::uint8_t> shard;
};

VoxelAccumulator::VoxelAccumulator(double leaf_size, std::size_t expected_points) {
  if (!(std::isfinite(leaf_size) && leaf_size > 0.0)) {
    throw std::invalid_argument("VoxelAccumulator: leaf_size must be finite and > 0, got " + std::to_string(leaf_size));
  }
  impl_ = std::make_unique<Impl>(expected_points);
  impl_->inv_leaf = 1.0 / leaf_size;
}

VoxelAccumulator::~VoxelAccumulator() = default;

void VoxelAccumulator::add(std::span<const Eigen::Vector4d> points, int num_threads) {
  if (points.size() > std::numeric_limits<std::uint32_t>::max() - added_) {
    throw std::length_error("VoxelAccumulator: more than 2^32 - 1 points added");
  }
  Impl& s = *impl_;
  // First every point's hash and shard (kDropped: non-finite or beyond any voxel), in pieces; then each
  // shard takes its points in their order.
  constexpr std::uint8_t kDropped = 0xFF;
  constexpr std::size_t kPiece = 8192;
  s.hash.resize(points.size());
  s.shard.resize(points.size());
  parallelFor(chunkCount(points.size(), kPiece), num_threads, [&](std::size_t piece) {
    const std::size_t end = std::min(points.size(), (piece + 1) * kPiece);
    for (std::size_t i = piece * kPiece; i < end; ++i) {
      detail::VoxelCoord c;
      if (!points[i].head<3>().allFinite() || !detail::voxelCoord(points[i], s.inv_leaf, &c)) {
        s.shard[i] = kDropped;
        continue;
      }
      const std::uint64_t h = detail::hashVoxel(c);
      s.hash[i] = static_cast<std::uint32_t>(h);
      s.shard[i] = static_cast<std::uint8_t>(shardOf(h));
    }
  });
  const auto base = static_cast<std::uint32_t>(added_);
  parallelFor(kShards, num_threads, [&](std::size_t shard) {
    Shard& mine = s.shards[shard];
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (s.shard[i] != shard) continue;
      detail::VoxelCoord c;
      detail::voxelCoord(points[i], s.inv_leaf, &c);
      mine.add(c, s.hash[i], points[i], base + static_cast<std::uint32_t>(i), s.inv_leaf);
    }
  });
  added_ += points.size();
  dropped_ += static_cast<std::size_t>(std::count(s.shard.begin(), s.shard.end(), kDropped));
}

std::size_t VoxelAccumulator::voxels() const {
  std::size_t n = 0;
  for (const Shard& shard : impl_->shards) n += shard.size();
  return n;
}

PointCloud VoxelAccumulator::centroids() const {
  // Each shard holds its voxels in the order of their first points: merged by that order, the centroids
  // come in the order their voxels were first hit, as voxelDownsample's.
  const auto& shards = impl_->shards;
  PointCloud out;
  out.points.resize(voxels());
  std::array<std::size_t, kShards> next{};
  for (auto& p : out.points) {
    std::size_t pick = kShards;
    for (std::size_t k = 0; k < kShards; ++k) {
      if (next[k] < shards[k].size() &&
          (pick == kShards || shards[k].at(next[k]).order < shards[pick].at(next[pick]).order))
        pick = k;
    }
    const Voxel& x = shards[pick].at(next[pick]++);
    p.head<3>() = x.first + x.sum / double(x.count);
    p.w() = 1.0;
  }
  return out;
}

}  // namespace rigcal::registration
