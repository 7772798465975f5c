#pragma once
// One ring's input as its writers counted it (shm::DriverTally, carried in every slot): the running totals
// of the current writer plus those of the writers before it, since a restarted driver counts from zero
// again. Written by the ring's reader thread, read by progress() and inputs() from any thread.
#include <cstdint>
#include <mutex>

#include "rigcal/shm/driver_tally.hpp"

namespace rigcal::pipeline::detail {

struct RingInputTotals {
  std::uint64_t packets = 0, malformed = 0, late_dropped = 0, reordered = 0, foreign = 0;
};

class RingInputTally {
 public:
  /// The tally a scan just read carries; `new_writer` if another writer published it than the previous one.
  void update(const shm::DriverTally& tally, bool new_writer);
  [[nodiscard]] RingInputTotals totals() const;

 private:
  mutable std::mutex mutex_;
  RingInputTotals earlier_writers_;
  shm::DriverTally current_;
  bool seen_ = false;
};

}  // namespace rigcal::pipeline::detail
