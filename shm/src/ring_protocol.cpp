#include "rigcal/shm/ring_protocol.hpp"

#include <algorithm>
#include <cstring>
#include <new>
#include <sstream>

#include "rigcal/shm/futex.hpp"
#include "rigcal/shm/liveness.hpp"
#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/ring_segment.hpp"
#include "memory_orders.hpp"
#include "shared_copy.hpp"

namespace rigcal::shm {

namespace {

using detail::kAcquire;
using detail::kRelaxed;
using detail::kRelease;
using detail::kSeqCst;

std::string hex(std::uint64_t v) {
  std::ostringstream s;
  s << "0x" << std::hex << v;
  return s.str();
}

/// Header fields that take part in the checksum, in this order, before the point arrays.
void sumHeader(detail::Checksum& sum, std::uint64_t points, std::uint64_t sequence, std::int64_t stamp,
               std::uint64_t missing, const DriverTally& tally, std::uint64_t writer_scan) {
  sum.add(points);
  sum.add(sequence);
  sum.add(static_cast<std::uint64_t>(stamp));
  sum.add(missing);
  sum.add(tally.packets);
  sum.add(std::uint64_t{tally.malformed} << 32 | tally.late_dropped);
  sum.add(std::uint64_t{tally.reordered} << 32 | tally.foreign);
  sum.add(writer_scan);
}

/// Copies the payload of `slot` into `out`; false if the point count is impossible or the checksum is off.
/// Either way the caller re-checks the sequence counter before trusting anything it copied.
bool copyOut(const RingView& ring, std::uint64_t index, Scan& out, ScanMeta* meta) {
  SlotHeader& s = ring.slotHeader(index);
  const SlotGeometry& g = ring.geometry();
  const std::uint32_t n = s.point_count.load(kAcquire);
  if (n > g.max_points) return false;
  const std::uint64_t sequence = s.sensor_sequence.load(kAcquire);
  const std::int64_t stamp = s.stamp_ns.load(kAcquire);
  const std::uint32_t missing = s.missing_packets.load(kAcquire);
  DriverTally tally;
  tally.packets = s.tally_packets.load(kAcquire);
  tally.malformed = s.tally_malformed.load(kAcquire);
  tally.late_dropped = s.tally_late_dropped.load(kAcquire);
  tally.reordered = s.tally_reordered.load(kAcquire);
  tally.foreign = s.tally_foreign.load(kAcquire);
  const std::uint64_t writer_scan = s.writer_scan.load(kAcquire);
  const std::uint64_t expected = s.checksum.load(kAcquire);
  if (meta) {
    meta->ring_index = index;
    meta->epoch = s.epoch.load(kAcquire);
    meta->publish_ns = s.publish_ns.load(kAcquire);
    meta->driver = tally;
    meta->writer_scan = writer_scan;
  }
  detail::Checksum sum;
  sumHeader(sum, n, sequence, stamp, missing, tally, writer_scan);
  // resize() stays within capacity once `out` has held a scan this large: no allocation in steady state.
  out.resize(n);
  std::byte* base = ring.slotBase(index);
  detail::copyFromShared(out.x.data(), base + g.x, 4u * n, sum);
  detail::copyFromShared(out.y.data(), base + g.y, 4u * n, sum);
  detail::copyFromShared(out.z.data(), base + g.z, 4u * n, sum);
  detail::copyFromShared(out.intensity.data(), base + g.intensity, 4u * n, sum);
  detail::copyFromShared(out.offset_ns.data(), base + g.offset_ns, 4u * n, sum);
  detail::copyFromShared(out.ring.data(), base + g.ring, 2u * n, sum);
  detail::copyFromShared(out.return_index.data(), base + g.return_index, n, sum);
  out.sequence = sequence;
  out.stamp_ns = stamp;
  out.missing_packets = missing;
  return sum.value() == expected;
}

}  // namespace

RingView::RingView(void* base, std::size_t bytes) {
  auto* header = std::launder(static_cast<RingHeader*>(base));
  if (bytes < sizeof(RingHeader) || bytes < header->total_bytes) {
    throw RingError(RingError::Kind::kCorrupted, "ring mapping smaller than its header says");
  }
  header_ = header;
  slots_ = static_cast<std::byte*>(base) + header->header_bytes;
  slot_count_ = header->slot_count;
  geometry_ = slotGeometry(header->max_points);
}

SlotHeader& RingView::slotHeader(std::uint64_t ring_index) const {
  return *std::launder(reinterpret_cast<SlotHeader*>(slotBase(ring_index)));
}

std::byte* RingView::slotBase(std::uint64_t ring_index) const {
  return slots_ + (ring_index % slot_count_) * geometry_.slot_bytes;
}

void initRing(void* base, const std::string& sensor_name, std::uint32_t slot_count,
              std::uint32_t max_points, std::uint64_t epoch) {
  auto* h = new (base) RingHeader{};  // value-initialised: every atomic 0, magic 0 until the end
  h->layout_version = kLayoutVersion;
  h->header_bytes = sizeof(RingHeader);
  h->layout_hash = kLayoutHash;
  h->slot_count = slot_count;
  h->max_points = max_points;
  h->slot_bytes = slotGeometry(max_points).slot_bytes;
  h->total_bytes = ringBytes(slot_count, max_points);
  const std::size_t len = std::min(sensor_name.size(), kSensorNameBytes - 1);
  std::memcpy(h->sensor_name, sensor_name.data(), len);
  h->epoch.store(epoch, kRelaxed);
  auto* slots = static_cast<std::byte*>(base) + sizeof(RingHeader);
  for (std::uint32_t i = 0; i < slot_count; ++i) new (slots + i * h->slot_bytes) SlotHeader{};
  h->magic.store(kRingMagic, kRelease);
}

HeaderState checkHeader(const void* base, std::size_t bytes, const std::string& segment) {
  const std::string where = "shared-memory ring '" + segment + "'";
  if (bytes < sizeof(std::uint64_t)) return HeaderState::kUninitialised;
  const auto* h = std::launder(static_cast<const RingHeader*>(base));
  const std::uint64_t magic = h->magic.load(kAcquire);
  if (magic == 0) return HeaderState::kUninitialised;
  if (magic != kRingMagic) {
    throw RingError(RingError::Kind::kCorrupted,
                    where + " is not a rigcal scan ring (magic " + hex(magic) + ", expected " +
                        hex(kRingMagic) + "); remove " + segmentPath(segment).string());
  }
  if (bytes < sizeof(RingHeader)) {
    throw RingError(RingError::Kind::kCorrupted, where + " is shorter (" + std::to_string(bytes) +
                                                     " bytes) than a ring header");
  }
  if (h->layout_version != kLayoutVersion || h->layout_hash != kLayoutHash) {
    throw RingError(RingError::Kind::kLayoutMismatch,
                    where + " has layout version " + std::to_string(h->layout_version) + " (hash " +
                        hex(h->layout_hash) + ") but this build reads layout version " +
                        std::to_string(kLayoutVersion) + " (hash " + hex(kLayoutHash) + ")");
  }
  const bool sane = h->header_bytes == sizeof(RingHeader) && h->slot_count >= kMinSlots &&
                    h->slot_count <= kMaxSlots && h->max_points >= 1 &&
                    h->max_points <= kMaxPointsLimit &&
                    h->slot_bytes == slotGeometry(h->max_points).slot_bytes &&
                    h->total_bytes == ringBytes(h->slot_count, h->max_points);
  if (!sane) {
    throw RingError(RingError::Kind::kCorrupted,
                    where + " has a corrupted header (slot_count " + std::to_string(h->slot_count) +
                        ", max_points " + std::to_string(h->max_points) + ", slot_bytes " +
                        std::to_string(h->slot_bytes) + ", total_bytes " + std::to_string(h->total_bytes) + ")");
  }
  if (bytes < h->total_bytes) {
    throw RingError(RingError::Kind::kCorrupted, where + " is " + std::to_string(bytes) +
                                                     " bytes long but its header says " +
                                                     std::to_string(h->total_bytes));
  }
  return HeaderState::kReady;
}

bool scanFits(const RingView& ring, const Scan& scan) {
  const std::size_t n = scan.x.size();
  return scan.y.size() == n && scan.z.size() == n && scan.intensity.size() == n &&
         scan.ring.size() == n && scan.offset_ns.size() == n && scan.return_index.size() == n &&
         n <= ring.geometry().max_points;
}

std::uint64_t beginPublish(const RingView& ring) {
  // Only this writer changes write_index, so a relaxed load sees its own last store.
  const std::uint64_t index = ring.header().write_index.load(kRelaxed);
  // Relaxed is enough: every payload store that follows is a release, which orders this one before it.
  ring.slotHeader(index).seq.store(2 * index + 1, kRelaxed);
  return index;
}

void writePayload(const RingView& ring, std::uint64_t index, const Scan& scan, std::uint64_t epoch,
                  const DriverTally& tally, std::uint64_t writer_scan) {
  SlotHeader& s = ring.slotHeader(index);
  const SlotGeometry& g = ring.geometry();
  const auto n = static_cast<std::uint32_t>(scan.size());
  detail::Checksum sum;
  sumHeader(sum, n, scan.sequence, scan.stamp_ns, scan.missing_packets, tally, writer_scan);
  std::byte* base = ring.slotBase(index);
  detail::copyToShared(base + g.x, scan.x.data(), 4u * n, sum);
  detail::copyToShared(base + g.y, scan.y.data(), 4u * n, sum);
  detail::copyToShared(base + g.z, scan.z.data(), 4u * n, sum);
  detail::copyToShared(base + g.intensity, scan.intensity.data(), 4u * n, sum);
  detail::copyToShared(base + g.offset_ns, scan.offset_ns.data(), 4u * n, sum);
  detail::copyToShared(base + g.ring, scan.ring.data(), 2u * n, sum);
  detail::copyToShared(base + g.return_index, scan.return_index.data(), n, sum);
  s.point_count.store(n, kRelease);
  s.sensor_sequence.store(scan.sequence, kRelease);
  s.stamp_ns.store(scan.stamp_ns, kRelease);
  s.missing_packets.store(scan.missing_packets, kRelease);
  s.tally_packets.store(tally.packets, kRelease);
  s.tally_malformed.store(tally.malformed, kRelease);
  s.tally_late_dropped.store(tally.late_dropped, kRelease);
  s.tally_reordered.store(tally.reordered, kRelease);
  s.tally_foreign.store(tally.foreign, kRelease);
  s.writer_scan.store(writer_scan, kRelease);
  s.epoch.store(epoch, kRelease);
  s.checksum.store(sum.value(), kRelease);
}

void commitPublish(const RingView& ring, std::uint64_t index, const Scan& scan) {
  RingHeader& h = ring.header();
  SlotHeader& s = ring.slotHeader(index);
  const std::int64_t now = monotonicNs();
  s.publish_ns.store(now, kRelease);
  s.seq.store(2 * index + 2, kRelease);
  h.last_stamp_ns.store(scan.stamp_ns, kRelaxed);
  h.total_points.store(h.total_points.load(kRelaxed) + scan.size(), kRelaxed);
  h.heartbeat_ns.store(now, kRelaxed);
  h.last_publish_ns.store(now, kRelaxed);
  // seq_cst: pairs with the reader's waiters increment and write_index re-check (see wakeReaders).
  h.write_index.store(index + 1, kSeqCst);
  wakeReaders(ring);
}

void wakeReaders(const RingView& ring) {
  RingHeader& h = ring.header();
  // A reader increments `waiters`, then re-reads write_index, then sleeps only while futex_word is unchanged.
  // With these operations seq_cst, either we see its increment (and call FUTEX_WAKE) or it sees our new
  // write_index (and does not sleep); a reader already asleep has a stale futex word and is woken.
  h.futex_word.fetch_add(1, kSeqCst);
  if (h.waiters.load(kSeqCst) != 0) futexWakeAll(h.futex_word);
}

std::uint64_t publishScan(const RingView& ring, const Scan& scan, std::uint64_t epoch, const DriverTally& tally,
                          std::uint64_t writer_scan) {
  const std::uint64_t index = beginPublish(ring);
  writePayload(ring, index, scan, epoch, tally, writer_scan);
  commitPublish(ring, index, scan);
  return index;
}

ReadOutcome readNext(const RingView& ring, std::uint64_t& next_index, Scan& out, ScanMeta* meta,
                     ReadCounters& counters) {
  const RingHeader& h = ring.header();
  const std::uint64_t slots = ring.slotCount();
  // Each failed attempt means the writer overtook us; bound the retries so a pathological writer (tiny
  // scans, tiny ring) cannot hold a reader here forever — the caller simply calls again.
  for (int attempt = 0; attempt < 64; ++attempt) {
    const std::uint64_t written = h.write_index.load(kAcquire);
    if (next_index >= written) return ReadOutcome::kEmpty;
    if (written - next_index > slots) {  // lapped: the scans before written − slots are gone
      counters.overruns += written - slots - next_index;
      next_index = written - slots;
    }
    const std::uint64_t index = next_index;
    const std::uint64_t want = 2 * index + 2;
    const std::uint64_t before = ring.slotHeader(index).seq.load(kAcquire);
    if (before != want) {  // already rewritten for a later scan (or being rewritten): this one is lost
      ++counters.overruns;
      ++next_index;
      continue;
    }
    const bool intact = copyOut(ring, index, out, meta);
    const std::uint64_t after = ring.slotHeader(index).seq.load(kAcquire);
    ++next_index;
    if (after != before) {  // the writer came back to this slot while we copied: discard the copy
      ++counters.torn_reads;
      ++counters.overruns;
      continue;
    }
    if (!intact) {
      ++counters.checksum_errors;
      continue;
    }
    return ReadOutcome::kScan;
  }
  return ReadOutcome::kEmpty;
}

}  // namespace rigcal::shm
