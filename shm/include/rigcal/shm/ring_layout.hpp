#pragma once
// The ScanRing shared-memory layout (DESIGN.md, "ScanRing layout"): one RingHeader, then `slot_count`
// fixed-size slots. Every field sits at a fixed offset and the payload holds offsets, never pointers, so
// each process may map the segment at any address. Whatever another process may change while we look is
// a lock-free (hence address-free) std::atomic; the identity block is written once, before `magic`.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace rigcal::shm {

inline constexpr std::uint64_t kRingMagic = 0x31474e4952534752ULL;  // "RGSRING1" read as little-endian
// 2: SlotHeader carries the driver's running tally (DriverTally) and takes two cache lines.
inline constexpr std::uint32_t kLayoutVersion = 2;
inline constexpr std::size_t kCacheLine = 64;
inline constexpr std::uint32_t kMaxReaders = 16;   // reader records the monitor can see
inline constexpr std::size_t kSensorNameBytes = 64;
inline constexpr std::uint32_t kMinSlots = 2;
inline constexpr std::uint32_t kMaxSlots = 1024;
inline constexpr std::uint32_t kMaxPointsLimit = 1u << 24;  // 16 M points: far above any lidar sweep

/// What the header says about its writer. Only the writer changes it.
enum class WriterState : std::uint32_t {
  kNone = 0,      // never had one (not used after init)
  kClaiming = 1,  // a new writer is taking the segment over (counts as alive)
  kRunning = 2,   // pid/start_time identify the writer; check them to see whether it still lives
  kClosed = 3,    // the writer shut down cleanly (and normally unlinked the segment)
};

/// One reader's counters, published for `rigcal monitor`. pid 0 = free, -1 = being claimed.
struct alignas(kCacheLine) ReaderRecord {
  std::atomic<std::int32_t> pid;
  std::atomic<std::uint32_t> reserved;
  std::atomic<std::uint64_t> start_time;  // /proc/<pid>/stat starttime, tells a recycled pid
  std::atomic<std::uint64_t> next_index;  // the ring index it waits for (backlog = write_index − this)
  std::atomic<std::uint64_t> scans;
  std::atomic<std::uint64_t> overruns;
  std::atomic<std::uint64_t> torn_reads;
  std::atomic<std::int64_t> active_ns;    // CLOCK_MONOTONIC of its last read or wait
};

struct alignas(kCacheLine) RingHeader {
  // Identity: written once by the creating writer, before `magic` (release). Never changes afterwards.
  std::atomic<std::uint64_t> magic;
  std::uint32_t layout_version;
  std::uint32_t header_bytes;  // sizeof(RingHeader) = offset of slot 0
  std::uint64_t layout_hash;
  std::uint32_t slot_count;
  std::uint32_t max_points;    // points one slot holds
  std::uint64_t slot_bytes;
  std::uint64_t total_bytes;   // header + slots: the segment size
  char sensor_name[kSensorNameBytes];

  // Writer identity and liveness.
  alignas(kCacheLine) std::atomic<std::uint32_t> writer_state;  // WriterState
  std::atomic<std::int32_t> writer_pid;
  std::atomic<std::uint64_t> writer_start_time;  // /proc/<pid>/stat field 22 (clock ticks since boot)
  std::atomic<std::uint64_t> epoch;              // +1 each time a writer (re)initialises the ring
  std::atomic<std::int64_t> heartbeat_ns;        // CLOCK_MONOTONIC, set by publish() and heartbeat()
  std::atomic<std::int64_t> last_stamp_ns;       // stamp_ns of the newest published scan
  std::atomic<std::int64_t> last_publish_ns;     // CLOCK_MONOTONIC when the newest scan became visible
  std::atomic<std::uint64_t> total_points;       // points published since the segment was created
  std::atomic<std::uint64_t> oversize_drops;     // scans the writer refused: more than max_points

  // Publication: readers poll write_index and sleep on futex_word.
  alignas(kCacheLine) std::atomic<std::uint64_t> write_index;  // scans published; scan n is in slot n % N
  std::atomic<std::uint32_t> futex_word;                       // bumped after each publish and on close
  std::atomic<std::uint32_t> waiters;                          // readers inside FUTEX_WAIT (may over-count)

  ReaderRecord readers[kMaxReaders];
};

/// At the start of every slot. seq = 2n+1 while scan n is being written into it, 2n+2 once it is complete;
/// scan n lives in slot n % slot_count, so the counter also says which scan the slot holds.
struct alignas(kCacheLine) SlotHeader {
  std::atomic<std::uint64_t> seq;
  std::atomic<std::uint64_t> sensor_sequence;
  std::atomic<std::int64_t> stamp_ns;
  std::atomic<std::int64_t> publish_ns;  // CLOCK_MONOTONIC when the payload was complete (before seq even)
  std::atomic<std::uint64_t> checksum;   // over the header fields below and the point arrays
  std::atomic<std::uint64_t> epoch;      // of the writer that wrote the slot
  std::atomic<std::uint32_t> point_count;
  std::atomic<std::uint32_t> missing_packets;
  // The writer's DriverTally when it published the scan (running totals, not per scan).
  std::atomic<std::uint64_t> tally_packets;
  std::atomic<std::uint32_t> tally_malformed;
  std::atomic<std::uint32_t> tally_late_dropped;
  std::atomic<std::uint32_t> tally_reordered;
  std::atomic<std::uint32_t> tally_foreign;
  std::atomic<std::uint64_t> writer_scan;  // scans this writer published before this one (0: its first)
};

/// Where each point array sits inside a slot, for a given capacity. Arrays start on cache lines.
struct SlotGeometry {
  std::uint32_t max_points = 0;
  std::uint64_t x = 0, y = 0, z = 0, intensity = 0, offset_ns = 0, ring = 0, return_index = 0;
  std::uint64_t slot_bytes = 0;
};

constexpr std::uint64_t alignUp(std::uint64_t v, std::uint64_t a) { return (v + a - 1) / a * a; }

/// Bytes one point takes in a slot: x y z intensity (float), offset_ns (u32), ring (u16), return (u8).
inline constexpr std::uint64_t kBytesPerPoint = 4 * 4 + 4 + 2 + 1;

constexpr SlotGeometry slotGeometry(std::uint32_t max_points) {
  SlotGeometry g;
  g.max_points = max_points;
  std::uint64_t off = sizeof(SlotHeader);
  auto place = [&](std::uint64_t element_bytes) {
    const std::uint64_t at = off;
    off = alignUp(off + element_bytes * max_points, kCacheLine);
    return at;
  };
  g.x = place(4);
  g.y = place(4);
  g.z = place(4);
  g.intensity = place(4);
  g.offset_ns = place(4);
  g.ring = place(2);
  g.return_index = place(1);
  g.slot_bytes = off;
  return g;
}

constexpr std::uint64_t ringBytes(std::uint32_t slot_count, std::uint32_t max_points) {
  return sizeof(RingHeader) + std::uint64_t{slot_count} * slotGeometry(max_points).slot_bytes;
}

// The layout hash: FNV-1a over the version, the sizes and the offsets of everything in the segment, so two
// builds that disagree on any of them refuse each other even if someone forgot to bump kLayoutVersion.
namespace detail {
constexpr std::uint64_t fnv1a(std::uint64_t h, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) {
    h ^= (v >> (8 * i)) & 0xffu;
    h *= 0x100000001b3ULL;
  }
  return h;
}
constexpr std::uint64_t computeLayoutHash() {
  const std::uint64_t parts[] = {
      kLayoutVersion, kMaxReaders, kSensorNameBytes, kCacheLine, kBytesPerPoint,
      sizeof(RingHeader), offsetof(RingHeader, magic), offsetof(RingHeader, layout_version),
      offsetof(RingHeader, header_bytes), offsetof(RingHeader, layout_hash),
      offsetof(RingHeader, slot_count), offsetof(RingHeader, max_points),
      offsetof(RingHeader, slot_bytes), offsetof(RingHeader, total_bytes),
      offsetof(RingHeader, sensor_name), offsetof(RingHeader, writer_state),
      offsetof(RingHeader, writer_pid), offsetof(RingHeader, writer_start_time),
      offsetof(RingHeader, epoch), offsetof(RingHeader, heartbeat_ns),
      offsetof(RingHeader, last_stamp_ns), offsetof(RingHeader, last_publish_ns),
      offsetof(RingHeader, total_points), offsetof(RingHeader, oversize_drops),
      offsetof(RingHeader, write_index), offsetof(RingHeader, futex_word),
      offsetof(RingHeader, waiters), offsetof(RingHeader, readers),
      sizeof(ReaderRecord), offsetof(ReaderRecord, pid), offsetof(ReaderRecord, start_time),
      offsetof(ReaderRecord, next_index), offsetof(ReaderRecord, scans),
      offsetof(ReaderRecord, overruns), offsetof(ReaderRecord, torn_reads),
      offsetof(ReaderRecord, active_ns),
      sizeof(SlotHeader), offsetof(SlotHeader, seq), offsetof(SlotHeader, sensor_sequence),
      offsetof(SlotHeader, stamp_ns), offsetof(SlotHeader, publish_ns),
      offsetof(SlotHeader, checksum), offsetof(SlotHeader, epoch),
      offsetof(SlotHeader, point_count), offsetof(SlotHeader, missing_packets),
      offsetof(SlotHeader, tally_packets), offsetof(SlotHeader, tally_malformed),
      offsetof(SlotHeader, tally_late_dropped), offsetof(SlotHeader, tally_reordered),
      offsetof(SlotHeader, tally_foreign), offsetof(SlotHeader, writer_scan),
      slotGeometry(1000).offset_ns, slotGeometry(1000).return_index, slotGeometry(1000).slot_bytes,
  };
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::uint64_t p : parts) h = fnv1a(h, p);
  return h;
}
}  // namespace detail

inline constexpr std::uint64_t kLayoutHash = detail::computeLayoutHash();

// Cross-process atomics must be lock-free (a lock would live in one process) and hence address-free.
static_assert(std::atomic<std::uint64_t>::is_always_lock_free);
static_assert(std::atomic<std::int64_t>::is_always_lock_free);
static_assert(std::atomic<std::uint32_t>::is_always_lock_free);
static_assert(std::atomic<std::int32_t>::is_always_lock_free);
static_assert(sizeof(std::atomic<std::uint32_t>) == 4, "the futex word must be a plain 32-bit word");
static_assert(std::is_standard_layout_v<RingHeader> && std::is_standard_layout_v<SlotHeader>);
static_assert(sizeof(SlotHeader) == 2 * kCacheLine);
static_assert(sizeof(RingHeader) % kCacheLine == 0);
static_assert(offsetof(RingHeader, magic) == 0);

}  // namespace rigcal::shm
