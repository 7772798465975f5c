#include "rigcal/shm/scan_ring_writer.hpp"

#include <cstring>
#include <stdexcept>

#include "rigcal/shm/liveness.hpp"
#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/ring_segment.hpp"
#include "segment.hpp"

namespace rigcal::shm {

struct ScanRingWriter::Impl {
  WriterOptions options;
  std::string name;
  detail::Segment segment;
  RingView view;
  std::uint64_t epoch = 0;
  bool took_over = false;
  bool open = false;
  WriterStats stats;

  void claim(const ProcessIdentity& me, std::uint64_t new_epoch);
  void openSegment();
};

namespace {

/// The one-line refusal when another process holds the writer lock.
std::string liveWriterMessage(detail::Segment& segment) {
  std::string who = "another process";
  try {
    segment.map();
    if (checkHeader(segment.base(), segment.mappedBytes(), segment.name()) == HeaderState::kReady) {
      const RingHeader& h = *static_cast<const RingHeader*>(segment.base());
      who = "pid " + std::to_string(h.writer_pid.load(std::memory_order_acquire));
    }
  } catch (const std::exception&) {
    // The lock holder is what matters; its header is only decoration for the message.
  }
  return "shared-memory ring '" + segment.name() + "' already has a live writer (" + who +
         "); only one writer per sensor";
}

}  // namespace

void ScanRingWriter::Impl::claim(const ProcessIdentity& me, std::uint64_t new_epoch) {
  RingHeader& h = view.header();
  // Readers treat kClaiming as alive, so the half-written identity below is never judged.
  h.writer_state.store(static_cast<std::uint32_t>(WriterState::kClaiming), std::memory_order_release);
  h.writer_pid.store(me.pid, std::memory_order_release);
  h.writer_start_time.store(me.start_time, std::memory_order_release);
  h.heartbeat_ns.store(monotonicNs(), std::memory_order_relaxed);
  h.epoch.store(new_epoch, std::memory_order_release);
  h.writer_state.store(static_cast<std::uint32_t>(WriterState::kRunning), std::memory_order_release);
  epoch = new_epoch;
  open = true;
  wakeReaders(view);  // sleeping readers notice the new epoch now rather than at their next liveness check
}

void ScanRingWriter::Impl::openSegment() {
  const ProcessIdentity me = selfIdentity();
  const std::uint64_t bytes = ringBytes(options.slot_count, options.max_points);
  std::uint64_t fresh_epoch = 1;
  for (int attempt = 0; attempt < 20; ++attempt) {
    std::optional<detail::Segment> seg = detail::Segment::create(name);
    const bool created = seg.has_value();
    if (!seg) seg = detail::Segment::open(name, true);
    if (!seg) continue;  // unlinked between our two calls: try again
    // The lock, not the header, decides ownership: the kernel releases it when its holder dies.
    if (!seg->tryLockExclusive()) throw RingError(RingError::Kind::kLiveWriter, liveWriterMessage(*seg));
    if (!seg->isStillNamed()) continue;  // another writer replaced it while we were locking
    if (!created) seg->requireOwnedPrivately();  // never adopt a ring another user could touch
    if (created || seg->size() == 0) {
      seg->truncate(bytes);
      seg->map(true);
      std::memset(seg->base(), 0, bytes);  // allocates every page now rather than during the first lap
      initRing(seg->base(), options.sensor, options.slot_count, options.max_points, fresh_epoch);
      segment = std::move(*seg);
      view = RingView(segment.base(), segment.mappedBytes());
      claim(me, fresh_epoch);
      return;
    }
    // A segment nobody writes: left behind by a dead writer. Take it over.
    seg->map(true);
    HeaderState state = HeaderState::kUninitialised;
    try {
      state = checkHeader(seg->base(), seg->mappedBytes(), name);
    } catch (const RingError& e) {
      if (e.kind() != RingError::Kind::kLayoutMismatch) throw;  // not ours to destroy: refuse
      removeSegment(name);  // an older or newer rigcal's ring: replace it with ours
      took_over = true;
      continue;
    }
    if (state == HeaderState::kUninitialised) {  // its creator died before finishing the header
      removeSegment(name);
      took_over = true;
      continue;
    }
    const RingHeader& h = *static_cast<const RingHeader*>(seg->base());
    const std::uint64_t old_epoch = h.epoch.load(std::memory_order_acquire);
    took_over = true;
    if (h.slot_count == options.slot_count && h.max_points == options.max_points) {
      // Same geometry: keep the segment and its write index (ring indices stay monotonic, so a reader's
      // cursor stays meaningful); a slot the dead writer left odd is rewritten by our next publish.
      segment = std::move(*seg);
      view = RingView(segment.base(), segment.mappedBytes());
      claim(me, old_epoch + 1);
      return;
    }
    fresh_epoch = old_epoch + 1;  // another size: a new segment; readers follow it by name
    removeSegment(name);
  }
  throw RingError(RingError::Kind::kSystem,
                  "shared-memory ring '" + name + "': could not claim the segment (it kept changing)");
}

ScanRingWriter::ScanRingWriter(const WriterOptions& options) : impl_(std::make_unique<Impl>()) {
  if (options.max_points < 1 || options.max_points > kMaxPointsLimit) {
    throw std::invalid_argument("shared-memory ring: max_points must be in [1, " +
                                std::to_string(kMaxPointsLimit) + "], not " +
                                std::to_string(options.max_points));
  }
  if (options.slot_count < kMinSlots || options.slot_count > kMaxSlots) {
    throw std::invalid_argument("shared-memory ring: slot_count must be in [" + std::to_string(kMinSlots) +
                                ", " + std::to_string(kMaxSlots) + "], not " +
                                std::to_string(options.slot_count));
  }
  impl_->options = options;
  impl_->name = shm::segmentName(options.sensor, options.name_prefix);
  impl_->openSegment();
}

ScanRingWriter::~ScanRingWriter() {
  if (!impl_) return;
  try {
    close();
  } catch (...) {
    // A destructor must not throw; the segment is then left for the next writer to take over.
  }
}

ScanRingWriter::ScanRingWriter(ScanRingWriter&&) noexcept = default;
ScanRingWriter& ScanRingWriter::operator=(ScanRingWriter&& other) noexcept {
  if (this != &other) {
    if (impl_) {
      try {
        close();
      } catch (...) {
      }
    }
    impl_ = std::move(other.impl_);
  }
  return *this;
}

bool ScanRingWriter::publish(const Scan& scan, const DriverTally& tally) {
  Impl& m = *impl_;
  if (!m.open) throw std::logic_error("ScanRingWriter::publish after close()");
  if (!scanFits(m.view, scan)) {
    const std::size_t n = scan.x.size();
    if (scan.y.size() != n || scan.z.size() != n || scan.intensity.size() != n || scan.ring.size() != n ||
        scan.offset_ns.size() != n || scan.return_index.size() != n) {
      throw std::invalid_argument("ScanRingWriter::publish: the scan's point arrays differ in length");
    }
    ++m.stats.oversize_drops;
    m.view.header().oversize_drops.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  publishScan(m.view, scan, m.epoch, tally, m.stats.published);
  ++m.stats.published;
  m.stats.points += scan.size();
  m.stats.bytes += payloadBytes(scan.size());
  return true;
}

void ScanRingWriter::heartbeat() {
  if (impl_->open) impl_->view.header().heartbeat_ns.store(monotonicNs(), std::memory_order_relaxed);
}

void ScanRingWriter::close() {
  Impl& m = *impl_;
  if (!m.open) return;
  m.open = false;
  m.view.header().writer_state.store(static_cast<std::uint32_t>(WriterState::kClosed),
                                     std::memory_order_release);
  wakeReaders(m.view);
  // We hold the lock, so nobody else can have replaced the segment — unless someone removed it by hand.
  if (m.segment.isStillNamed()) removeSegment(m.name);
  m.view = RingView();
  m.segment = detail::Segment();  // unmaps and closes: releases the writer lock
}

const std::string& ScanRingWriter::segmentName() const { return impl_->name; }
std::uint64_t ScanRingWriter::epoch() const { return impl_->epoch; }
bool ScanRingWriter::tookOver() const { return impl_->took_over; }
const WriterStats& ScanRingWriter::stats() const { return impl_->stats; }
const RingView& ScanRingWriter::view() const { return impl_->view; }

}  // namespace rigcal::shm
