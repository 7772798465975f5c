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
  if (points_.size() > run_start_) runs_.push_back(Run{points_.size(), run_start_, run_start_});
  run_start_ = points_.size();
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
    const std::int64_t last = buckets_[run.end - 1];
    top = any ? std::max(top, last) : last;
    any = true;
  }
  if (any) emit(top, out);
  released_.reset();
  compact();
}

void AzimuthOrder::emit(std::int64_t up_to, DecodedPacket& out) {
  // Buckets below `lo` were released before: such points are late and go first, in arrival order.
  std::int64_t lo = 0;
  if (released_) {
    lo = *released_ + 1;
  } else {
    bool any = false;
    for (std::size_t r = run_head_; r < runs_.size(); ++r)
      if (runs_[r].cursor < runs_[r].end) {
        const std::int64_t b = buckets_[runs_[r].cursor];
        lo = any ? std::min(lo, b) : b;
        any = true;
      }
    if (!any) return;
  }
  const std::size_t base = out.points.size();
  if (up_to < lo || up_to - lo + 1 > kMaxCountingRange) {
    emitBySort(up_to, lo, base, out);
    return;
  }

  // Counting sort over [lo, up_to]; slot 0 holds late points. One pass finds each run's released
  // prefix (runs are sorted) and counts it, a second places the points.
  const std::size_t range = static_cast<std::size_t>(up_to - lo + 1);
  counts_.assign(range + 1, 0);
  std::size_t total = 0;
  for (std::size_t r = run_head_; r < runs_.size(); ++r) {
    Run& run = runs_[r];
    std::size_t i = run.cursor;
    for (; i < run.end; ++i) {
      const std::int64_t b = buckets_[i];
      if (b > up_to) break;
      ++counts_[b < lo ? 0 : static_cast<std::size_t>(b - lo) + 1];
    }
    run.scan_end = i;
    total += i - run.cursor;
  }
  if (total == 0) return;
  bucket_az_.resize(range + 1);
  std::uint32_t pos = 0;
  for (std::size_t k = 0; k <= range; ++k) {
    const std::uint32_t n = counts_[k];
    counts_[k] = pos;
    pos += n;
    if (k > 0 && n > 0) bucket_az_[k] = bucketAzimuthDeg(lo + static_cast<std::int64_t>(k) - 1);
  }
  // Slot of each released point, then the points in slot order (appended: no zero-filling).
  if (slots_.size() < total) slots_.resize(total);
  for (std::size_t r = run_head_; r < runs_.size(); ++r) {
    Run& run = runs_[r];
    for (std::size_t i = run.cursor; i < run.scan_end; ++i) {
      const std::int64_t b = buckets_[i];
      slots_[counts_[b < lo ? 0 : static_cast<std::size_t>(b - lo) + 1]++] = static_cast<std::uint32_t>(i);
    }
    run.cursor = run.scan_end;
  }
  for (std::size_t s = 0; s < total; ++s) {
    const std::uint32_t i = slots_[s];
    const std::int64_t b = buckets_[i];
    out.points.push_back(points_[i]);
    out.azimuth_deg.push_back(b < lo ? bucketAzimuthDeg(b) : bucket_az_[static_cast<std::size_t>(b - lo) + 1]);
  }
}

void AzimuthOrder::emitBySort(std::int64_t up_to, std::int64_t lo, std::size_t base, DecodedPacket& out) {
  spill_.clear();
  for (std::size_t r = run_head_; r < runs_.size(); ++r) {
    Run& run = runs_[r];
    for (; run.cursor < run.end && buckets_[run.cursor] <= up_to; ++run.cursor)
      spill_.emplace_back(std::max(buckets_[run.cursor], lo - 1), run.cursor);
  }
  std::stable_sort(spill_.begin(), spill_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  out.points.resize(base + spill_.size());
  out.azimuth_deg.resize(base + spill_.size());
  std::size_t pos = base;
  for (const auto& [key, i] : spill_) {
    out.points[pos] = points_[i];
    out.azimuth_deg[pos] = bucketAzimuthDeg(buckets_[i]);
    ++pos;
  }
}

void AzimuthOrder::compact() {
  while (run_head_ < runs_.size() && runs_[run_head_].cursor == runs_[run_head_].end) ++run_head_;
  if (run_head_ == runs_.size()) {
    // Everything released: start over, keeping capacity (no allocation in steady state).
    runs_.clear();
    run_head_ = 0;
    points_.erase(points_.begin(), points_.begin() + static_cast<std::ptrdiff_t>(run_start_));
    buckets_.erase(buckets_.begin(), buckets_.begin() + static_cast<std::ptrdiff_t>(run_start_));
    run_start_ = 0;
    return;
  }
  const std::size_t first = runs_[run_head_].cursor;
  if (first > 16384 && first * 2 > points_.size()) {
    points_.erase(points_.begin(), points_.begin() + static_cast<std::ptrdiff_t>(first));
    buckets_.erase(buckets_.begin(), buckets_.begin() + static_cast<std::ptrdiff_t>(first));
    for (std::size_t r = run_head_; r < runs_.size(); ++r) {
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
