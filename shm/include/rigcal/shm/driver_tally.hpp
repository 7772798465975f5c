#pragma once
// What a ring's writer (a `rigcal driver` process) has counted of its input so far: running totals since it
// started, carried in every slot so a reader in another process can report a damaged input per sensor as
// an in-process driver's counters would (the scan itself carries only the packets lost inside it).
#include <cstdint>

namespace rigcal::shm {

struct DriverTally {
  std::uint64_t packets = 0;       // data packets decoded
  std::uint32_t malformed = 0;     // packets and frames dropped as malformed (decoder and source)
  std::uint32_t late_dropped = 0;  // packets older than one already assembled
  std::uint32_t reordered = 0;     // packets put back in order
  std::uint32_t foreign = 0;       // packets of another model on its port, ignored

  friend bool operator==(const DriverTally&, const DriverTally&) = default;
};

}  // namespace rigcal::shm
