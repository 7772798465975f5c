#pragma once
// Counters a writer and a reader keep, and the writer's state as a reader or the monitor sees it.
#include <cstdint>

namespace rigcal::shm {

enum class WriterStatus {
  kAbsent,   // no segment (yet), or one still being created
  kAlive,    // pid and start time match a running process, heartbeat fresh
  kStalled,  // the process lives but has not published or sent a heartbeat for `stall_after`
  kDead,     // the process is gone (or its pid now belongs to another process): the segment is stale
  kClosed,   // the writer shut down cleanly
};

const char* toString(WriterStatus status);

struct WriterStats {
  std::uint64_t published = 0;       // scans published by this writer
  std::uint64_t points = 0;
  std::uint64_t bytes = 0;           // payload bytes copied into the ring
  std::uint64_t oversize_drops = 0;  // scans refused: more points than a slot holds
};

struct ReaderStats {
  std::uint64_t scans = 0;            // scans returned intact
  std::uint64_t points = 0;
  std::uint64_t bytes = 0;            // payload bytes copied out
  std::uint64_t overruns = 0;         // scans lost because the writer lapped this reader
  std::uint64_t torn_reads = 0;       // copies discarded because the slot changed meanwhile (each also lost a scan)
  std::uint64_t checksum_errors = 0;  // copies with a stable counter but a wrong checksum (never expected)
  std::uint64_t writer_restarts = 0;  // epoch changes seen (a new writer took over)
  std::uint64_t reattaches = 0;       // times the reader mapped a new segment under the same name
};

}  // namespace rigcal::shm
