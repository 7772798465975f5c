#pragma once
// One ring's input as its writers counted it (shm::DriverTally, carried in every slot) while we read it:
// the running totals of the current writer plus those of the writers before it, since a restarted driver
// counts from zero again. A writer whose first scan we did not read (we attached to a driver that had been
// running) is counted from the first scan we read, not since it started. Written by the ring's reader
// thread, read by progress() and inputs() from any thread.
#include <cstdint>
#include <mutex>

#include "rigcal/shm/driver_tally.hpp"

namespace rigcal::pipeline::detail {

struct RingInputTotals {
  std::uint64_t packets = 0, malformed = 0, late_dropped = 0, reordered = 0, foreign = 0;
};

class RingInputTally {
 public:
  /// The tally a scan just read carries, and how many scans its writer published before it;
  /// `new_writer` if another writer published it than the previous one.
  void update(const shm::DriverTally& tally, std::uint64_t writer_scan, bool new_writer);
  [[nodiscard]] RingInputTotals totals() const;

 private:
  mutable std::mutex mutex_;
  RingInputTotals earlier_writers_;
  shm::DriverTally current_, baseline_;  // baseline_: the current writer's tally before we read from it
  bool seen_ = false;
};

}  // namespace rigcal::pipeline::detail
