#pragma once
// One reader of a sensor's ScanRing. Readers never slow the writer: one that falls behind by more than
// the ring holds loses the oldest scans (counted as overruns) and continues with the oldest still there.
// read() copies a scan out into a caller-owned Scan (reusing its capacity: no allocation in steady state)
// and sleeps on the ring's futex while there is nothing new — it never spins. While it waits it checks the
// writer every `liveness_period`: a dead writer is reported (writerStatus()), a new writer is followed —
// in place (epoch change) or in a new segment under the same name (mapped again once the old one is
// drained). A segment with another layout version is refused with a one-line RingError naming both, and
// so is one another user owns or other users may write (kForeign, checked before mapping it). A segment
// truncated under the reader is detached from and reported (RingError kCorrupted), not touched: the size is
// checked before the header or a slot is read (a truncation during the copy of one slot still faults).
// A reader is used from one thread.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "rigcal/core/scan.hpp"
#include "rigcal/shm/ring_protocol.hpp"
#include "rigcal/shm/ring_stats.hpp"

namespace rigcal::shm {

struct ReaderOptions {
  std::string sensor;
  std::optional<std::string> name_prefix;  // default: $RIGCAL_SHM_PREFIX, else "rigcal."
  /// Where to start in a ring that already exists when the reader is created. A ring that appears later
  /// (or a new writer's new segment) is always read from its oldest scan.
  enum class StartAt { kNext, kOldest } start_at = StartAt::kNext;
  std::chrono::milliseconds liveness_period{100};  // writer checks while waiting; also the attach poll
  std::chrono::milliseconds stall_after{2000};     // heartbeat age that makes a live writer "stalled"
  bool publish_stats = true;  // take a reader record in the header so `rigcal monitor` shows our counters
};

enum class ReadStatus {
  kScan,        // `out` holds the next scan
  kTimeout,     // nothing new within the timeout
  kWriterGone,  // the writer closed or died and every scan it published has been read; returned once per
                // writer, as soon as a liveness check sees it. Keep calling read(): a new writer is followed.
};

class ScanRingReader {
 public:
  /// Attaches now if the ring exists. Throws RingError (layout mismatch, corrupted header, foreign ring).
  explicit ScanRingReader(const ReaderOptions& options);
  ~ScanRingReader();
  ScanRingReader(ScanRingReader&&) noexcept;
  ScanRingReader& operator=(ScanRingReader&&) noexcept;

  /// The next scan, waiting at most `timeout` for one. `out` is unspecified unless kScan.
  /// Throws RingError if a ring that appears meanwhile has another layout, a corrupted header or a foreign
  /// owner or mode, or if the ring was truncated (the reader is then detached from it).
  ReadStatus read(Scan& out, std::chrono::nanoseconds timeout, ScanMeta* meta = nullptr);
  /// read() without waiting.
  bool tryRead(Scan& out, ScanMeta* meta = nullptr);

  /// The writer's status now (reads /proc; cheap, but not for every scan).
  WriterStatus writerStatus();
  [[nodiscard]] bool attached() const;
  /// The epoch of the writer generation last seen.
  [[nodiscard]] std::uint64_t epoch() const;
  /// Scans published in the ring but not yet read by this reader.
  [[nodiscard]] std::uint64_t backlog() const;
  [[nodiscard]] const ReaderStats& stats() const;
  [[nodiscard]] const std::string& segmentName() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigcal::shm
