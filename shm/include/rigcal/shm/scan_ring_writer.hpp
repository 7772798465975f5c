#pragma once
// The single writer of a sensor's ScanRing "/<prefix><sensor>" (default prefix "rigcal."). Creating one
// claims the segment: a fresh one is created; a stale one left by a dead writer is taken over (same
// geometry: in place, epoch + 1; other geometry or layout: unlinked and created anew); a segment whose writer
// still runs is refused. publish() never waits for readers and never allocates. The destructor (or close())
// marks the ring closed, wakes the readers and unlinks the segment.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "rigcal/core/scan.hpp"
#include "rigcal/shm/ring_protocol.hpp"
#include "rigcal/shm/ring_stats.hpp"

namespace rigcal::shm {

struct WriterOptions {
  std::string sensor;                      // ring name = prefix + sensor
  std::uint32_t max_points = 0;            // slot capacity: the sensor's largest scan
  std::uint32_t slot_count = 8;            // scans kept for slow readers
  std::optional<std::string> name_prefix;  // default: $RIGCAL_SHM_PREFIX, else "rigcal."
};

class ScanRingWriter {
 public:
  /// Throws RingError: kLiveWriter (another process writes this ring), kCorrupted (the name holds something
  /// that is not a rigcal ring), kSystem; std::invalid_argument for impossible options.
  explicit ScanRingWriter(const WriterOptions& options);
  ~ScanRingWriter();
  ScanRingWriter(ScanRingWriter&&) noexcept;
  ScanRingWriter& operator=(ScanRingWriter&&) noexcept;

  /// Publishes a copy of `scan`, with what its driver has counted so far, and wakes waiting readers. False
  /// (scan dropped, counted) if it has more points than a slot holds. Throws std::invalid_argument if its
  /// arrays differ in length.
  bool publish(const Scan& scan, const DriverTally& tally = {});
  /// Tells readers this writer is alive while it has nothing to publish (publish() does it too).
  void heartbeat();
  /// Marks the ring closed, wakes readers, unlinks the segment. Idempotent; the destructor calls it.
  void close();

  [[nodiscard]] const std::string& segmentName() const;
  [[nodiscard]] std::uint64_t epoch() const;
  /// True if the constructor took over a segment left behind by a dead writer.
  [[nodiscard]] bool tookOver() const;
  [[nodiscard]] const WriterStats& stats() const;
  /// The mapped ring, for tools and tests (e.g. to simulate a writer that dies mid-write).
  [[nodiscard]] const RingView& view() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigcal::shm
