#include "ring_input_tally.hpp"

namespace rigcal::pipeline::detail {

namespace {

void add(RingInputTotals& sum, const shm::DriverTally& t) {
  sum.packets += t.packets;
  sum.malformed += t.malformed;
  sum.late_dropped += t.late_dropped;
  sum.reordered += t.reordered;
  sum.foreign += t.foreign;
}

}  // namespace

void RingInputTally::update(const shm::DriverTally& tally, bool new_writer) {
  std::lock_guard lock(mutex_);
  if (new_writer && seen_) add(earlier_writers_, current_);
  current_ = tally;
  seen_ = true;
}

RingInputTotals RingInputTally::totals() const {
  std::lock_guard lock(mutex_);
  RingInputTotals t = earlier_writers_;
  add(t, current_);
  return t;
}

}  // namespace rigcal::pipeline::detail
