#include "rigcal/shm/scan_ring_reader.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <ctime>

#include "rigcal/shm/futex.hpp"
#include "rigcal/shm/liveness.hpp"
#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/ring_segment.hpp"
#include "memory_orders.hpp"
#include "segment.hpp"
#include "sigbus_guard.hpp"

namespace rigcal::shm {

namespace {

using detail::kAcquire;
using detail::kRelaxed;
using detail::kRelease;
using detail::kSeqCst;

void sleepNs(std::int64_t ns) {
  if (ns <= 0) return;
  timespec ts{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  ::nanosleep(&ts, nullptr);
}

}  // namespace

struct ScanRingReader::Impl {
  ReaderOptions options;
  std::string name;
  ProcessIdentity me;
  detail::Segment segment;
  RingView view;
  bool attached = false;
  bool ever_attached = false;
  std::uint64_t next_index = 0;
  std::uint64_t epoch = 0;
  int record = -1;
  WriterStatus status = WriterStatus::kAbsent;
  bool gone_reported = false;  // kWriterGone already returned for the current writer
  std::int64_t next_liveness_ns = 0;
  ReadCounters counters;
  ReaderStats stats;

  bool tryAttach(bool use_start_option);
  void detach();
  [[nodiscard]] bool shrunk() const noexcept;
  void requireIntact();
  [[noreturn]] void reportTruncated(const char* when);
  std::unique_ptr<detail::TruncationShield> shield;  // over the mapping while attached
  void claimRecord();
  void releaseRecord();
  void publishRecord();
  void syncCounters();
  bool checkLiveness();
};

bool ScanRingReader::Impl::tryAttach(bool use_start_option) {
  std::optional<detail::Segment> seg = detail::Segment::open(name, true);
  if (!seg) return false;  // none yet
  seg->requireOwnedPrivately();  // the writer's rule: never read a ring another user could have prepared
  if (seg->size() < sizeof(RingHeader)) return false;  // its writer is creating it
  seg->map(true);
  if (checkHeader(seg->base(), seg->mappedBytes(), name) == HeaderState::kUninitialised) return false;
  segment = std::move(*seg);
  view = RingView(segment.base(), segment.mappedBytes());
  shield = std::make_unique<detail::TruncationShield>(segment.base(), segment.mappedBytes());
  attached = true;
  const RingHeader& h = view.header();
  if (ever_attached) {  // a new segment under our name: a new writer
    ++stats.reattaches;
    ++stats.writer_restarts;
  }
  ever_attached = true;
  epoch = h.epoch.load(kAcquire);
  const std::uint64_t written = h.write_index.load(kAcquire);
  const bool from_next = use_start_option && options.start_at == ReaderOptions::StartAt::kNext;
  next_index = from_next ? written : written - std::min<std::uint64_t>(written, view.slotCount());
  status = evaluateWriter(h, options.stall_after);
  gone_reported = false;
  next_liveness_ns = monotonicNs() + options.liveness_period.count() * 1'000'000;
  claimRecord();
  return true;
}

void ScanRingReader::Impl::detach() {
  releaseRecord();
  view = RingView();
  shield.reset();
  segment = detail::Segment();  // unmaps (the zero pages too, if the shield tripped)
  attached = false;
}

/// Touching a mapped page past the end of a truncated segment raises SIGBUS, so the size is checked before
/// the header or a slot is read. A ring shrunk under us (only its owner can, see requireOwnedPrivately) is
/// dropped without writing to it and reported as a RingError naming it.
bool ScanRingReader::Impl::shrunk() const noexcept {
  struct stat st {};
  return attached && (::fstat(segment.fd(), &st) != 0 || std::uint64_t(st.st_size) < segment.mappedBytes());
}

void ScanRingReader::Impl::requireIntact() {
  if (shrunk() || (shield && shield->tripped()))
    reportTruncated(shield && shield->tripped() ? "while being read (SIGBUS caught: zero pages mapped in its place)"
                                                : "while being read");
}

void ScanRingReader::Impl::reportTruncated(const char* when) {
  const std::uint64_t mapped = segment.mappedBytes();
  struct stat st {};
  const long long now = ::fstat(segment.fd(), &st) == 0 ? st.st_size : -1;
  record = -1;  // its record may be gone with the pages: do not release it
  detach();
  throw RingError(RingError::Kind::kCorrupted, "shared-memory ring '" + name + "' was truncated to " +
                                                   std::to_string(now) + " of its " + std::to_string(mapped) +
                                                   " bytes " + when + ": detached from it");
}

void ScanRingReader::Impl::claimRecord() {
  if (!options.publish_stats) return;
  RingHeader& h = view.header();
  for (std::uint32_t i = 0; i < kMaxReaders; ++i) {
    ReaderRecord& r = h.readers[i];
    std::int32_t pid = r.pid.load(kAcquire);
    const bool free = pid == 0 || (pid > 0 && !processAlive({pid, r.start_time.load(kAcquire)}));
    // -1 marks the record as being claimed, so nobody judges it by a half-written identity.
    if (!free || !r.pid.compare_exchange_strong(pid, -1, std::memory_order_acq_rel)) continue;
    r.start_time.store(me.start_time, kRelaxed);
    r.scans.store(0, kRelaxed);
    r.overruns.store(0, kRelaxed);
    r.torn_reads.store(0, kRelaxed);
    r.next_index.store(next_index, kRelaxed);
    r.active_ns.store(monotonicNs(), kRelaxed);
    r.pid.store(me.pid, kRelease);
    record = static_cast<int>(i);
    return;
  }
}

void ScanRingReader::Impl::releaseRecord() {
  if (record < 0 || !attached || shrunk()) return;
  view.header().readers[record].pid.store(0, kRelease);
  record = -1;
}

void ScanRingReader::Impl::publishRecord() {
  if (record < 0) return;
  ReaderRecord& r = view.header().readers[record];
  r.next_index.store(next_index, kRelaxed);
  r.scans.store(stats.scans, kRelaxed);
  r.overruns.store(stats.overruns, kRelaxed);
  r.torn_reads.store(stats.torn_reads, kRelaxed);
}

void ScanRingReader::Impl::syncCounters() {
  stats.overruns = counters.overruns;
  stats.torn_reads = counters.torn_reads;
  stats.checksum_errors = counters.checksum_errors;
}

/// Re-evaluates the writer. True when it has just been found gone (closed or dead) with everything it
/// published already read: the moment read() reports kWriterGone.
bool ScanRingReader::Impl::checkLiveness() {
  const RingHeader& h = view.header();
  status = evaluateWriter(h, options.stall_after);
  if (record >= 0) view.header().readers[record].active_ns.store(monotonicNs(), kRelaxed);
  if (status != WriterStatus::kDead && status != WriterStatus::kClosed) {
    gone_reported = false;
    return false;
  }
  if (next_index < h.write_index.load(kAcquire)) return false;  // its scans first
  const bool report = !gone_reported;
  gone_reported = true;
  // See whether a new writer made a new segment under our name (a clean shutdown unlinks; a takeover with
  // another geometry recreates).
  if (segment.isStillNamed()) return report;
  const WriterStatus last = status;
  detach();
  status = last;
  if (tryAttach(false)) return false;  // already following the new writer
  return report;
}

ScanRingReader::ScanRingReader(const ReaderOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->name = shm::segmentName(options.sensor, options.name_prefix);
  impl_->me = selfIdentity();
  impl_->tryAttach(true);
}

ScanRingReader::~ScanRingReader() {
  if (impl_) impl_->releaseRecord();
}

ScanRingReader::ScanRingReader(ScanRingReader&&) noexcept = default;
ScanRingReader& ScanRingReader::operator=(ScanRingReader&& other) noexcept {
  if (this != &other) {
    if (impl_) impl_->releaseRecord();
    impl_ = std::move(other.impl_);
  }
  return *this;
}

ReadStatus ScanRingReader::read(Scan& out, std::chrono::nanoseconds timeout, ScanMeta* meta) {
  Impl& m = *impl_;
  const std::int64_t period = m.options.liveness_period.count() * 1'000'000;
  const std::int64_t deadline = monotonicNs() + std::max<std::int64_t>(0, timeout.count());
  for (;;) {
    if (!m.attached) {
      if (m.tryAttach(false)) continue;  // a ring that appears later is read from its oldest scan
      const std::int64_t now = monotonicNs();
      if (now >= deadline) return ReadStatus::kTimeout;
      sleepNs(std::min(period, deadline - now));  // poll for the segment to appear, 10 times a second
      continue;
    }
    m.requireIntact();
    RingHeader& h = m.view.header();
    // A truncation after requireIntact's check turns the mapping into zero pages (TruncationShield): this
    // pass reads nothing, the next check reports it.
    if (const std::uint64_t e = h.epoch.load(kAcquire); e != m.epoch) {  // a new writer took over in place
      ++m.stats.writer_restarts;
      m.epoch = e;
      m.status = evaluateWriter(h, m.options.stall_after);
      m.gone_reported = false;
    }
    if (readNext(m.view, m.next_index, out, meta, m.counters) == ReadOutcome::kScan) {
      if (out.sensor_id != m.options.sensor) out.sensor_id = m.options.sensor;
      ++m.stats.scans;
      m.stats.points += out.size();
      m.stats.bytes += payloadBytes(out.size());
      m.syncCounters();
      m.publishRecord();
      return ReadStatus::kScan;
    }
    m.syncCounters();
    m.publishRecord();
    std::int64_t now = monotonicNs();
    if (now >= m.next_liveness_ns) {
      const bool gone = m.checkLiveness();
      m.next_liveness_ns = now + period;
      if (gone) return ReadStatus::kWriterGone;
      if (!m.attached || &h != &m.view.header()) continue;  // detached or re-attached: start over
    }
    if (now >= deadline) return ReadStatus::kTimeout;
    // Sleep until the writer publishes (see wakeReaders for why these operations are seq_cst).
    const std::uint32_t seen = h.futex_word.load(kSeqCst);
    h.waiters.fetch_add(1, kSeqCst);
    const bool ready = h.write_index.load(kSeqCst) > m.next_index || h.epoch.load(kSeqCst) != m.epoch;
    if (!ready) futexWait(h.futex_word, seen, std::chrono::nanoseconds(std::min(deadline, m.next_liveness_ns) - now));
    m.requireIntact();  // it may have shrunk while we slept
    h.waiters.fetch_sub(1, kSeqCst);
    // A clean close also bumps the futex word: look at the writer now rather than at the next period.
    if (m.status != WriterStatus::kClosed &&
        h.writer_state.load(kAcquire) == static_cast<std::uint32_t>(WriterState::kClosed)) {
      m.next_liveness_ns = monotonicNs();
    }
  }
}

bool ScanRingReader::tryRead(Scan& out, ScanMeta* meta) {
  return read(out, std::chrono::nanoseconds(0), meta) == ReadStatus::kScan;
}

WriterStatus ScanRingReader::writerStatus() {
  Impl& m = *impl_;
  if (m.attached) m.requireIntact();
  if (m.attached) m.status = evaluateWriter(m.view.header(), m.options.stall_after);
  return m.status;
}

bool ScanRingReader::attached() const { return impl_->attached; }
std::uint64_t ScanRingReader::epoch() const { return impl_->epoch; }
std::uint64_t ScanRingReader::backlog() const {
  const Impl& m = *impl_;
  if (!m.attached || m.shrunk()) return 0;
  const std::uint64_t written = m.view.header().write_index.load(kAcquire);
  return written > m.next_index ? written - m.next_index : 0;
}
const ReaderStats& ScanRingReader::stats() const { return impl_->stats; }
const std::string& ScanRingReader::segmentName() const { return impl_->name; }

}  // namespace rigcal::shm
