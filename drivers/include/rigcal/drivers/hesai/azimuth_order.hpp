#pragma once
// Hands points on in non-decreasing order of their own azimuth (block azimuth + the channel's
// azimuth offset), so that a scan cut at angle C separates them exactly by that azimuth, as nebula
// (Hesai's reference decoder) does. Without it a PandarQT128, whose channel offsets reach ±10°,
// would interleave points from both sides of the cut over 50 packets.
//
// Azimuths are kept as integer buckets 0.01° wide (the block azimuth unit), unwrapped over turns;
// bucket b holds corrected azimuths in (b·0.01°, (b+1)·0.01°] — a point exactly on the cut angle
// belongs to the sweep that ends there, as in nebula. The order is exact for cut angles on the 0.01°
// grid. Points wait until no later firing can land in their bucket; a point is held at most the
// channel-offset span (QT128 ≈ 20°, XT32 ≈ 0.2°).
#include <cstdint>
#include <optional>
#include <vector>

#include "rigcal/core/scan.hpp"
#include "rigcal/drivers/packet_decoder.hpp"

namespace rigcal::drivers::hesai {

class AzimuthOrder {
 public:
  /// Adds one point of the current run; within a run buckets must not decrease.
  void push(const Point& point, std::int64_t bucket) { emplace(bucket) = point; }
  /// Adds a point in `bucket` and returns it for the caller to fill in.
  Point& emplace(std::int64_t bucket) {
    buckets_.push_back(bucket);
    return points_.emplace_back();
  }
  /// Closes the run of points pushed since the last endRun().
  void endRun();
  /// Appends to `out` (points and azimuth_deg) every held point whose bucket is ≤ up_to, sorted by
  /// bucket. The caller promises that points pushed later (in order) have buckets > up_to; a later
  /// point that breaks the promise (a late packet) is emitted at the next release, unsorted.
  void release(std::int64_t up_to, DecodedPacket& out);
  /// Appends every held point, sorted, and forgets the release history.
  void releaseAll(DecodedPacket& out);
  [[nodiscard]] std::size_t held() const;

  /// The reported azimuth of a bucket: its centre, in [0, 360).
  static float bucketAzimuthDeg(std::int64_t bucket);

 private:
  struct Run {
    std::size_t end, cursor, scan_end;
  };
  void emit(std::int64_t up_to, DecodedPacket& out);
  void emitBySort(std::int64_t up_to, std::int64_t lo, std::size_t base, DecodedPacket& out);
  void compact();

  std::vector<Point> points_;            // held points, runs one after another
  std::vector<std::int64_t> buckets_;    // their buckets
  std::vector<Run> runs_;
  std::size_t run_head_ = 0;
  std::size_t run_start_ = 0;             // first item of the run being pushed
  std::optional<std::int64_t> released_;  // highest bucket already released
  std::vector<std::uint32_t> counts_;     // reused counting-sort histogram
  std::vector<float> bucket_az_;
  std::vector<std::pair<std::int64_t, std::size_t>> spill_;  // fallback sort for wide ranges
  std::vector<std::uint32_t> slots_;     // counting sort: item (relative to its batch) per output slot
};

}  // namespace rigcal::drivers::hesai
