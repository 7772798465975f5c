#include "rigcal/pipeline/latency_histogram.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace rigcal::pipeline {

int LatencyHistogram::bucketOf(std::int64_t ns) {
  const std::uint64_t v = std::uint64_t(std::max<std::int64_t>(ns, 0));
  if (v < std::uint64_t(kSub)) return int(v);  // exact below 32 ns
  const int magnitude = std::bit_width(v) - 1;  // v in [2^m, 2^(m+1))
  const int sub = int((v >> (magnitude - kSubBits)) & (kSub - 1));
  return std::min((magnitude - kSubBits + 1) * kSub + sub, kBuckets - 1);
}

std::int64_t LatencyHistogram::upperEdge(int bucket) {
  if (bucket < kSub) return bucket;
  const int magnitude = bucket / kSub + kSubBits - 1;
  const int sub = bucket % kSub;
  return std::int64_t((std::uint64_t(kSub + sub + 1) << (magnitude - kSubBits)) - 1);
}

void LatencyHistogram::record(std::int64_t ns) {
  ++buckets_[std::size_t(bucketOf(ns))];
  ++count_;
  min_ = std::min(min_, ns);
  max_ = std::max(max_, ns);
}

void LatencyHistogram::merge(const LatencyHistogram& other) {
  for (std::size_t i = 0; i < buckets_.size(); ++i) buckets_[i] += other.buckets_[i];
  count_ += other.count_;
  min_ = std::min(min_, other.min_);
  max_ = std::max(max_, other.max_);
}

std::int64_t LatencyHistogram::quantile(double q) const {
  if (count_ == 0) return 0;
  const auto rank = std::uint64_t(std::ceil(std::clamp(q, 0.0, 1.0) * double(count_)));
  std::uint64_t seen = 0;
  for (int b = 0; b < kBuckets; ++b) {
    seen += buckets_[std::size_t(b)];
    if (seen >= std::max<std::uint64_t>(rank, 1)) return std::min(upperEdge(b), max_);
  }
  return max_;
}

}  // namespace rigcal::pipeline
