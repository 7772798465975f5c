#pragma once
// The ring protocol on mapped memory, independent of how the memory was mapped: a sequence lock per slot,
// a ring-wide write index and a futex word. ScanRingWriter and ScanRingReader add the segment management
// (naming, ownership, liveness); tests drive this layer directly from two threads on one buffer so that
// ThreadSanitizer sees both sides of every access.
//
// Memory ordering. Scan n goes to slot n % N. The writer stores seq = 2n+1, then the payload, then
// seq = 2n+2 (release), then write_index = n+1. Every payload word is accessed through std::atomic_ref:
// the writer stores with release, the reader loads with acquire. A reader that sees any word of a later
// write therefore also sees that write's odd seq when it re-checks, so a torn copy is always detected;
// and no access is a data race in the C++ model. On x86-64 these are the plain MOVs a memcpy loop would
// use (no fences exist on this path: GCC rejects std::atomic_thread_fence under -fsanitize=thread).
#include <cstddef>
#include <cstdint>
#include <string>

#include "rigcal/core/scan.hpp"
#include "rigcal/shm/driver_tally.hpp"
#include "rigcal/shm/ring_layout.hpp"

namespace rigcal::shm {

/// What a reader learns about a scan besides its contents.
struct ScanMeta {
  std::uint64_t ring_index = 0;  // position in the ring's publication order (continues across writers)
  std::uint64_t epoch = 0;       // epoch of the writer that published it
  std::int64_t publish_ns = 0;   // CLOCK_MONOTONIC when it was complete in its slot, just before it became visible
  DriverTally driver;            // its writer's running tally when it published the scan
  std::uint64_t writer_scan = 0;  // scans its writer published before it: 0 = the writer's first, so the
                                  // tally covers everything that writer counted
};

/// A mapped ring: header and slots, wherever this process mapped them.
class RingView {
 public:
  RingView() = default;
  /// `base` holds `bytes` bytes of a ring that initRing() laid out or checkHeader() accepted.
  RingView(void* base, std::size_t bytes);

  [[nodiscard]] bool valid() const { return header_ != nullptr; }
  [[nodiscard]] RingHeader& header() const { return *header_; }
  [[nodiscard]] std::uint32_t slotCount() const { return slot_count_; }
  [[nodiscard]] const SlotGeometry& geometry() const { return geometry_; }
  /// The slot scan `ring_index` goes to.
  [[nodiscard]] SlotHeader& slotHeader(std::uint64_t ring_index) const;
  [[nodiscard]] std::byte* slotBase(std::uint64_t ring_index) const;

 private:
  RingHeader* header_ = nullptr;
  std::byte* slots_ = nullptr;
  std::uint32_t slot_count_ = 0;
  SlotGeometry geometry_{};
};

/// Lays a new ring out in zeroed memory of ringBytes(slot_count, max_points) bytes. The identity is
/// written first and `magic` last (release), so a reader that sees the magic sees a complete header.
void initRing(void* base, const std::string& sensor_name, std::uint32_t slot_count,
              std::uint32_t max_points, std::uint64_t epoch);

enum class HeaderState { kReady, kUninitialised };

/// Checks the header of a mapped segment of `bytes` bytes called `segment`. kUninitialised while the magic
/// is still 0 (its writer is creating it). Throws RingError, one line: kLayoutMismatch naming both layout
/// versions and hashes, kCorrupted for a bad magic or fields that contradict each other.
HeaderState checkHeader(const void* base, std::size_t bytes, const std::string& segment);

// ---- Writer side: one writer at a time (ScanRingWriter enforces it with an flock on the segment).

/// True if `scan`'s arrays all have the same length, which is at most the slot capacity.
[[nodiscard]] bool scanFits(const RingView& ring, const Scan& scan);

/// Publishes `scan` (which must fit) with its writer's `tally` as ring index write_index and wakes
/// sleeping readers; returns the index.
std::uint64_t publishScan(const RingView& ring, const Scan& scan, std::uint64_t epoch, const DriverTally& tally = {},
                          std::uint64_t writer_scan = 0);

/// The steps of publishScan, exposed so a test can stop between them (a writer dying mid-write).
std::uint64_t beginPublish(const RingView& ring);  // seq odd; returns the index being written
void writePayload(const RingView& ring, std::uint64_t index, const Scan& scan, std::uint64_t epoch,
                  const DriverTally& tally = {}, std::uint64_t writer_scan = 0);
void commitPublish(const RingView& ring, std::uint64_t index, const Scan& scan);  // seq even, index+1, wake

/// Bumps the futex word and wakes every sleeping reader (after a publish, on close, after a takeover).
void wakeReaders(const RingView& ring);

// ---- Reader side: any number of readers, each with its own cursor (the next ring index it wants).

struct ReadCounters {
  std::uint64_t overruns = 0;         // scans lost because the writer lapped this reader
  std::uint64_t torn_reads = 0;       // copies discarded because the slot changed during the copy
  std::uint64_t checksum_errors = 0;  // copies with a stable counter but a wrong checksum
};

enum class ReadOutcome { kScan, kEmpty };

/// Copies scan `next_index` into `out` — or, if the writer lapped the reader, the oldest scan still in the
/// ring, counting the lost ones — and advances next_index past it. Reuses out's capacity (no allocation
/// once it has held a scan this large). kEmpty: nothing at or after next_index is published yet; `out` is
/// then unspecified. Never returns a scan whose slot changed during the copy.
ReadOutcome readNext(const RingView& ring, std::uint64_t& next_index, Scan& out, ScanMeta* meta,
                     ReadCounters& counters);

/// Payload bytes of a scan of `points` points (what the ring copies).
constexpr std::uint64_t payloadBytes(std::uint64_t points) { return points * kBytesPerPoint; }

}  // namespace rigcal::shm
