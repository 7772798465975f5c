#pragma once
// A read-only look at a ring, for `rigcal monitor`: header counters, writer status and the published
// counters of its readers. Never changes the segment.
#include <chrono>
#include <cstdint>
#include <string>

#include "rigcal/shm/ring_stats.hpp"

namespace rigcal::shm {

struct RingInfo {
  std::string segment;
  bool present = false;
  std::string error;  // why the segment could not be read (layout mismatch, corrupted), else empty
  std::string sensor;
  WriterStatus writer = WriterStatus::kAbsent;
  std::int32_t writer_pid = 0;
  std::uint64_t epoch = 0;
  std::uint32_t slot_count = 0;
  std::uint32_t max_points = 0;
  std::uint64_t total_bytes = 0;
  std::uint64_t write_index = 0;   // scans published
  std::uint64_t total_points = 0;  // points published
  std::uint64_t oversize_drops = 0;
  std::int64_t last_stamp_ns = 0;
  std::int64_t last_publish_ns = 0;  // CLOCK_MONOTONIC
  std::uint32_t readers = 0;         // live readers with a record
  std::uint64_t overruns = 0;        // summed over live readers
  std::uint64_t torn_reads = 0;
  std::uint64_t max_backlog = 0;     // scans the slowest live reader has yet to read
  std::int64_t sampled_ns = 0;       // CLOCK_MONOTONIC of this look
};

RingInfo inspectRing(const std::string& segment,
                     std::chrono::nanoseconds stall_after = std::chrono::seconds(2));

}  // namespace rigcal::shm
