#include "rigcal/shm/ring_inspect.hpp"

#include <algorithm>
#include <cstring>

#include "rigcal/shm/liveness.hpp"
#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/ring_protocol.hpp"
#include "segment.hpp"

namespace rigcal::shm {

RingInfo inspectRing(const std::string& segment, std::chrono::nanoseconds stall_after) {
  constexpr auto kAcquire = std::memory_order_acquire;
  constexpr auto kRelaxed = std::memory_order_relaxed;
  RingInfo info;
  info.segment = segment;
  info.sampled_ns = monotonicNs();
  try {
    std::optional<detail::Segment> seg = detail::Segment::open(segment, false);
    if (!seg) return info;
    info.present = true;
    seg->requireOwnedPrivately();
    if (seg->size() < sizeof(RingHeader)) return info;  // being created
    seg->map();
    if (checkHeader(seg->base(), seg->mappedBytes(), segment) == HeaderState::kUninitialised) return info;
    const RingHeader& h = *static_cast<const RingHeader*>(seg->base());
    info.sensor.assign(h.sensor_name, strnlen(h.sensor_name, kSensorNameBytes));
    info.writer = evaluateWriter(h, stall_after);
    info.writer_pid = h.writer_pid.load(kAcquire);
    info.epoch = h.epoch.load(kAcquire);
    info.slot_count = h.slot_count;
    info.max_points = h.max_points;
    info.total_bytes = h.total_bytes;
    info.write_index = h.write_index.load(kAcquire);
    info.total_points = h.total_points.load(kRelaxed);
    info.oversize_drops = h.oversize_drops.load(kRelaxed);
    info.last_stamp_ns = h.last_stamp_ns.load(kRelaxed);
    info.last_publish_ns = h.last_publish_ns.load(kRelaxed);
    for (const ReaderRecord& r : h.readers) {
      const std::int32_t pid = r.pid.load(kAcquire);
      if (pid <= 0 || !processAlive({pid, r.start_time.load(kAcquire)})) continue;
      ++info.readers;
      info.overruns += r.overruns.load(kRelaxed);
      info.torn_reads += r.torn_reads.load(kRelaxed);
      const std::uint64_t next = r.next_index.load(kRelaxed);
      if (info.write_index > next) info.max_backlog = std::max(info.max_backlog, info.write_index - next);
    }
  } catch (const RingError& e) {
    info.error = e.what();
  }
  return info;
}

}  // namespace rigcal::shm
