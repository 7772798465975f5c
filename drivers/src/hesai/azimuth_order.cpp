#include "rigcal/drivers/hesai/azimuth_order.hpp"

#include <algorithm>

namespace rigcal::drivers::hesai {
namespace {
constexpr std::int64_t kBucketsPerTurn = 36000;
constexpr std::int64_t kMaxCountingRange = 1 << 16;
}  // namespace

float AzimuthOrder::bucketAzimuthDeg(std::int64_t bucket) {
  const std::int64_t b = ((bucket % kBucketsPerTurn) + kBucketsPerTurn) % kBucketsPerTurn;
  return (static_cast<float>(b) + 0.5f) * 0.01f;
}

void AzimuthOrder::endRun() {
  if (items_.size() > run_start_) runs_.push_back(Run{run_start_, items_.size(), run_start_, run_start_});
  run_start_ = items_.size();
}

std::size_t AzimuthOrder::held() const {
  std::size_t n = 0;
  for (std::size_t r = run_head_; r < runs_.size(); ++r) n += runs_[r].end - runs_[r].cursor;
  return n;
}

void AzimuthOrder::release(std::int64_t up_to, DecodedPacket& out) {
  emit(up_to, out);
  released_ = released_ ? std::max(*released_, up_to) : up_to;
  compact();
}

void AzimuthOrder::releaseAll(DecodedPacket& out) {
  bool any = false;
  std::int64_t top = 0;
  for (std::size_t r = run_head_; r < runs_.size(); ++r) {
    const Run& run = runs_[r];
    if (run.cursor == run.end) continue;
    const std::int64_t last = items_[run.end - 1].bucket;
    top = any ? std::max(top, last) : last;
    any = true;
  }
  if (any) emit(top, out);
  released_.reset();
  compact();
}

void AzimuthOrder::emit(std::int64_t up_to, DecodedPacket& out) {
  // Pass 1: what each run releases (a sorted prefix), and the lowest bucket among it.
  std::size_t total = 0;
  std::optional<std::int64_t> lowest;
  for (std::size_t r = run_head_; r < runs_.size(); ++r) {
    Run& run = runs_[r];
    std::size_t i = run.cursor;
    while (i < run.end && items_[i].bucket <= up_to) ++i;
    run.scan_end = i;
    if (i > run.cursor) {
      total += i - run.cursor;
      const std::int64_t b = items_[run.cursor].bucket;
      lowest = lowest ? std::min(*lowest, b) : b;
    }
  }
  if (total == 0) return;

  // Buckets at or below what was released before are late: they go first, in arrival order.
  const std::int64_t lo = released_ ? std::max(*released_ + 1, *lowest) : *lowest;
  const std::size_t base = out.points.size();
  out.points.resize(base + total);
  out.azimuth_deg.resize(base + total);

  if (up_to < lo || up_to - lo + 1 > kMaxCountingRange) {
    spill_.clear();
    for (std::size_t r = run_head_; r < runs_.size(); ++r)
      for (std::size_t i = runs_[r].cursor; i < runs_[r].scan_end; ++i)
        spill_.emplace_back(std::max(items_[i].bucket, lo - 1), i);
    std::stable_sort(spill_.begin(), spill_.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::size_t pos = base;
    for (const auto& [bucket, i] : spill_) {
      out.points[pos] = items_[i].point;
      out.azimuth_deg[pos] = bucketAzimuthDeg(items_[i].bucket);
      ++pos;
    }
  } else {
    // Counting sort over the bucket range [lo, up_to]; slot 0 holds late points.
    const std::size_t range = static_cast<std::size_t>(up_to - lo + 1);
    counts_.assign(range + 1, 0);
    for (std::size_t r = run_head_; r < runs_.size(); ++r)
      for (std::size_t i = runs_[r].cursor; i < runs_[r].scan_end; ++i) {
        const std::int64_t b = items_[i].bucket;
        ++counts_[b < lo ? 0 : static_cast<std::size_t>(b - lo) + 1];
      }
    bucket_az_.resize(range + 1);
    std::uint32_t pos = static_cast<std::uint32_t>(base);
    for (std::size_t k = 0; k <= range; ++k) {
      const std::uint32_t n = counts_[k];
      counts_[k] = pos;
      pos += n;
      if (k > 0 && n > 0) bucket_az_[k] = bucketAzimuthDeg(lo + static_cast<std::int64_t>(k) - 1);
    }
    for (std::size_t r = run_head_; r < runs_.size(); ++r)
      for (std::size_t i = runs_[r].cursor; i < runs_[r].scan_end; ++i) {
        const std::int64_t b = items_[i].bucket;
        const std::size_t k = b < lo ? 0 : static_cast<std::size_t>(b - lo) + 1;
        const std::uint32_t at = counts_[k]++;
        out.points[at] = items_[i].point;
        out.azimuth_deg[at] = k == 0 ? bucketAzimuthDeg(b) : bucket_az_[k];
      }
  }
  for (std::size_t r = run_head_; r < runs_.size(); ++r) runs_[r].cursor = runs_[r].scan_end;
}

void AzimuthOrder::compact() {
  while (run_head_ < runs_.size() && runs_[run_head_].cursor == runs_[run_head_].end) ++run_head_;
  if (run_head_ == runs_.size()) {
    // Everything released: start over (keeps capacity, no allocation).
    runs_.clear();
    run_head_ = 0;
    // Points of a run still being pushed stay.
    if (run_start_ < items_.size()) {
      items_.erase(items_.begin(), items_.begin() + static_cast<std::ptrdiff_t>(run_start_));
    } else {
      items_.clear();
    }
    run_start_ = 0;
    return;
  }
  const std::size_t first = runs_[run_head_].cursor;
  if (first > 4096 && first * 2 > items_.size()) {
    items_.erase(items_.begin(), items_.begin() + static_cast<std::ptrdiff_t>(first));
    for (std::size_t r = run_head_; r < runs_.size(); ++r) {
      runs_[r].begin = runs_[r].begin > first ? runs_[r].begin - first : 0;
      runs_[r].end -= first;
      runs_[r].cursor -= first;
      runs_[r].scan_end -= first;
    }
    run_start_ -= first;
  }
  if (run_head_ > 256 && run_head_ * 2 > runs_.size()) {
    runs_.erase(runs_.begin(), runs_.begin() + static_cast<std::ptrdiff_t>(run_head_));
    run_head_ = 0;
  }
}

}  // namespace rigcal::drivers::hesai
