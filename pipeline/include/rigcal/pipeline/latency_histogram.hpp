#pragma once
// Latency histogram with ~3% relative resolution from 1 µs to ~70 s: 64 power-of-two ranges, each
// split into 32 linear buckets (HdrHistogram's idea in a few lines). One writer; read after join or
// via a snapshot taken by the writer.
#include <array>
#include <cstdint>

namespace rigcal::pipeline {

class LatencyHistogram {
 public:
  void record(std::int64_t ns);
  void merge(const LatencyHistogram& other);
  [[nodiscard]] std::uint64_t count() const { return count_; }
  [[nodiscard]] std::int64_t max() const { return max_; }
  [[nodiscard]] std::int64_t min() const { return count_ ? min_ : 0; }
  /// The value below which a fraction q of the samples lie (upper edge of its bucket), q in [0, 1].
  [[nodiscard]] std::int64_t quantile(double q) const;

 private:
  static constexpr int kSubBits = 5;
  static constexpr int kSub = 1 << kSubBits;
  static constexpr int kBuckets = 64 * kSub;
  static int bucketOf(std::int64_t ns);
  static std::int64_t upperEdge(int bucket);

  std::array<std::uint64_t, kBuckets> buckets_{};
  std::uint64_t count_ = 0;
  std::int64_t min_ = INT64_MAX;
  std::int64_t max_ = 0;
};

}  // namespace rigcal::pipeline
