#include "ring_input_tally.hpp"

namespace rigcal::pipeline::detail {

namespace {

// Adds what `writer` counted after `baseline` (both its running totals, which only grow).
void add(RingInputTotals& sum, const shm::DriverTally& writer, const shm::DriverTally& baseline) {
  const auto since = [](std::uint64_t now, std::uint64_t then) { return now >= then ? now - then : 0; };
  sum.packets += since(writer.packets, baseline.packets);
  sum.malformed += since(writer.malformed, baseline.malformed);
  sum.late_dropped += since(writer.late_dropped, baseline.late_dropped);
  sum.reordered += since(writer.reordered, baseline.reordered);
  sum.foreign += since(writer.foreign, baseline.foreign);
}

}  // namespace

void RingInputTally::update(const shm::DriverTally& tally, std::uint64_t writer_scan, bool new_writer) {
  std::lock_guard lock(mutex_);
  if (new_writer && seen_) add(earlier_writers_, current_, baseline_);
  if (new_writer || !seen_) baseline_ = writer_scan == 0 ? shm::DriverTally{} : tally;
  current_ = tally;
  seen_ = true;
}

RingInputTotals RingInputTally::totals() const {
  std::lock_guard lock(mutex_);
  RingInputTotals t = earlier_writers_;
  add(t, current_, baseline_);
  return t;
}

}  // namespace rigcal::pipeline::detail
