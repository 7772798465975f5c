// The layout and the seqlock protocol on one buffer shared by two threads (so ThreadSanitizer sees both
// sides of every access — across processes it cannot).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <thread>

#include "rigcal/shm/futex.hpp"
#include "rigcal/shm/liveness.hpp"
#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/ring_protocol.hpp"
#include "scan_pattern.hpp"
#include "sanitizers.hpp"

namespace rigcal::shm {
namespace {

struct FreeDeleter {
  void operator()(void* p) const { std::free(p); }
};

/// A zeroed, page-aligned buffer holding an initialised ring.
std::unique_ptr<void, FreeDeleter> makeRing(std::uint32_t slots, std::uint32_t max_points, RingView& view) {
  const std::size_t bytes = alignUp(ringBytes(slots, max_points), 4096);
  void* p = std::aligned_alloc(4096, bytes);
  std::memset(p, 0, bytes);
  initRing(p, "lidar", slots, max_points, 1);
  view = RingView(p, bytes);
  return std::unique_ptr<void, FreeDeleter>(p);
}

TEST(RingLayout, SlotArraysAreAlignedDisjointAndLargeEnough) {
  for (std::uint32_t n : {1u, 7u, 1000u, 240'000u}) {
    const SlotGeometry g = slotGeometry(n);
    const std::uint64_t offsets[] = {g.x, g.y, g.z, g.intensity, g.offset_ns, g.ring, g.return_index};
    const std::uint64_t sizes[] = {4, 4, 4, 4, 4, 2, 1};
    std::uint64_t end = sizeof(SlotHeader);
    for (int i = 0; i < 7; ++i) {
      EXPECT_EQ(offsets[i] % kCacheLine, 0u) << n;
      EXPECT_GE(offsets[i], end) << n;
      end = offsets[i] + sizes[i] * n;
    }
    EXPECT_LE(end, g.slot_bytes);
    EXPECT_EQ(g.slot_bytes % kCacheLine, 0u);
  }
  // A VLS-128 sweep (~240 k points) takes ~5.5 MB a slot.
  EXPECT_LT(slotGeometry(240'000).slot_bytes, 5'600'000u);
}

TEST(RingLayout, HashIsACompileTimeFunctionOfTheLayout) {
  static_assert(kLayoutHash != 0);
  constexpr std::uint64_t again = detail::computeLayoutHash();
  static_assert(again == kLayoutHash);
  EXPECT_EQ(sizeof(RingHeader) % kCacheLine, 0u);
  EXPECT_EQ(offsetof(RingHeader, write_index) % kCacheLine, 0u);  // the hot word has its own cache line
}

TEST(RingLayout, CheckHeaderTellsUninitialisedCorruptAndForeignLayouts) {
  RingView view;
  auto ring = makeRing(4, 100, view);
  const std::size_t bytes = ringBytes(4, 100);
  EXPECT_EQ(checkHeader(ring.get(), bytes, "r"), HeaderState::kReady);
  EXPECT_THROW((void)checkHeader(ring.get(), bytes - 1, "r"), RingError);  // shorter than it says

  auto& h = view.header();
  h.layout_version = 7;
  try {
    (void)checkHeader(ring.get(), bytes, "r");
    FAIL() << "layout mismatch accepted";
  } catch (const RingError& e) {
    EXPECT_EQ(e.kind(), RingError::Kind::kLayoutMismatch);
    const std::string msg = e.what();
    EXPECT_NE(msg.find("layout version 7"), std::string::npos) << msg;
    EXPECT_NE(msg.find("layout version " + std::to_string(kLayoutVersion)), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
  h.layout_version = kLayoutVersion;
  h.slot_count = 0;
  EXPECT_THROW((void)checkHeader(ring.get(), bytes, "r"), RingError);
  h.slot_count = 4;
  h.magic.store(0);
  EXPECT_EQ(checkHeader(ring.get(), bytes, "r"), HeaderState::kUninitialised);
  h.magic.store(0x1234);
  EXPECT_THROW((void)checkHeader(ring.get(), bytes, "r"), RingError);
}

TEST(RingProtocol, PublishThenReadRoundTripsEveryField) {
  RingView view;
  auto ring = makeRing(4, 1000, view);
  Scan in;
  test::fillPattern(in, 42, test::patternPoints(42, 1000));
  ASSERT_TRUE(scanFits(view, in));
  EXPECT_EQ(publishScan(view, in, 1), 0u);

  std::uint64_t next = 0;
  Scan out;
  ScanMeta meta;
  ReadCounters counters;
  ASSERT_EQ(readNext(view, next, out, &meta, counters), ReadOutcome::kScan);
  EXPECT_EQ(test::checkPattern(out, 1000), "");
  EXPECT_EQ(meta.ring_index, 0u);
  EXPECT_EQ(meta.epoch, 1u);
  EXPECT_EQ(next, 1u);
  EXPECT_EQ(readNext(view, next, out, &meta, counters), ReadOutcome::kEmpty);
}

// The writer's tally (issue 18: a driver process's malformed packets) crosses the ring with each scan and is
// covered by the slot checksum: a flipped count is a checksum error, never a wrong number.
TEST(RingProtocol, TheDriversTallyRoundTripsAndIsChecksummed) {
  RingView view;
  auto ring = makeRing(4, 100, view);
  Scan in;
  test::fillPattern(in, 7, test::patternPoints(7, 100));
  const DriverTally tally{123456789012ULL, 5, 6, 7, 8};
  publishScan(view, in, 1, tally, 9);
  std::uint64_t next = 0;
  Scan out;
  ScanMeta meta;
  ReadCounters counters;
  ASSERT_EQ(readNext(view, next, out, &meta, counters), ReadOutcome::kScan);
  EXPECT_EQ(meta.driver, tally);
  EXPECT_EQ(meta.writer_scan, 9u);

  publishScan(view, in, 1, tally);
  view.slotHeader(1).tally_malformed.store(50);  // as a stray write would
  EXPECT_EQ(readNext(view, next, out, &meta, counters), ReadOutcome::kEmpty);
  EXPECT_EQ(counters.checksum_errors, 1u);
}

TEST(RingProtocol, LappedReaderSkipsToOldestAndCountsEveryLostScan) {
  RingView view;
  auto ring = makeRing(4, 100, view);
  Scan in;
  for (std::uint64_t s = 0; s < 10; ++s) {
    test::fillPattern(in, s, test::patternPoints(s, 100));
    publishScan(view, in, 1);
  }
  std::uint64_t next = 0;
  Scan out;
  ReadCounters counters;
  ASSERT_EQ(readNext(view, next, out, nullptr, counters), ReadOutcome::kScan);
  EXPECT_EQ(out.sequence, 6u);  // scans 6..9 are the four still in the ring
  EXPECT_EQ(counters.overruns, 6u);
  int more = 0;
  while (readNext(view, next, out, nullptr, counters) == ReadOutcome::kScan) ++more;
  EXPECT_EQ(more, 3);
}

TEST(RingProtocol, SlotLeftOddByADeadWriterIsNeverReturned) {
  RingView view;
  auto ring = makeRing(4, 100, view);
  Scan in;
  for (std::uint64_t s = 0; s < 4; ++s) {
    test::fillPattern(in, s, test::patternPoints(s, 100));
    publishScan(view, in, 1);
  }
  // Writer "dies" while writing scan 4 into slot 0 (which held scan 0).
  test::fillPattern(in, 99, 100);
  const std::uint64_t index = beginPublish(view);
  writePayload(view, index, in, 1);
  std::uint64_t next = 0;
  Scan out;
  ReadCounters counters;
  std::vector<std::uint64_t> got;
  while (readNext(view, next, out, nullptr, counters) == ReadOutcome::kScan) {
    EXPECT_EQ(test::checkPattern(out, 100), "");
    got.push_back(out.sequence);
  }
  EXPECT_EQ(got, (std::vector<std::uint64_t>{1, 2, 3}));
  EXPECT_EQ(counters.overruns, 1u);  // scan 0, overwritten
}

// The core concurrency test: a writer thread far faster than the reader, a small ring, both on one buffer.
// Every scan returned must be intact; every scan published must be either returned or counted as lost.
TEST(RingProtocol, ConcurrentWriterAndReaderNeverYieldATornScan) {
  constexpr std::uint32_t kMax = 2000;
  constexpr std::uint64_t kScans = 3000;
  RingView view;
  auto ring = makeRing(3, kMax, view);
  std::atomic<bool> done{false};
  std::thread writer([&] {
    Scan s;
    for (std::uint64_t q = 0; q < kScans; ++q) {
      test::fillPattern(s, q, test::patternPoints(q, kMax));
      publishScan(view, s, 1);
    }
    done.store(true);
    wakeReaders(view);
  });
  std::uint64_t next = 0, got = 0, bad = 0;
  ReadCounters counters;
  Scan out;
  RingHeader& h = view.header();
  while (next < kScans) {
    if (readNext(view, next, out, nullptr, counters) == ReadOutcome::kScan) {
      ++got;
      if (!test::checkPattern(out, kMax).empty()) ++bad;
      continue;
    }
    const std::uint32_t seen = h.futex_word.load();
    h.waiters.fetch_add(1);
    if (h.write_index.load() <= next && !done.load()) futexWait(h.futex_word, seen, std::chrono::milliseconds(50));
    h.waiters.fetch_sub(1);
  }
  writer.join();
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(counters.checksum_errors, 0u);
  EXPECT_EQ(got + counters.overruns, kScans);
  EXPECT_GT(got, 0u);
  std::printf("[ info ] got %llu, overruns %llu, torn %llu\n", static_cast<unsigned long long>(got),
              static_cast<unsigned long long>(counters.overruns),
              static_cast<unsigned long long>(counters.torn_reads));
}

// A writer republishes two ready-made 1 M-point scans (23 MB, milliseconds to copy) back to back into a
// 2-slot ring, so the reader's copies do get torn: by the writer running on the other core, or — on a loaded
// machine where the two threads take turns — by the writer running while the reader is preempted mid-copy.
// Each torn copy must be detected and dropped, never returned (a mix of the two would fail checkPattern).
// Runs until it has seen 3 torn copies, at most 5 s.
TEST(RingProtocol, TornCopiesAreDetectedAndDiscarded) {
#if RIGCAL_SANITIZED
  constexpr std::uint32_t kMax = 200'000;  // instrumented copies are 10-50x slower: as long, fewer points
#else
  constexpr std::uint32_t kMax = 1'000'000;
#endif
  RingView view;
  auto ring = makeRing(2, kMax, view);
  Scan a, b;
  test::fillPattern(a, 0, test::patternPoints(0, kMax));
  test::fillPattern(b, 1, test::patternPoints(1, kMax));
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    for (std::uint64_t i = 0; !stop.load(std::memory_order_relaxed); ++i) publishScan(view, i % 2 ? b : a, 1);
  });
  std::uint64_t next = 0, got = 0, bad = 0;
  ReadCounters counters;
  Scan out;
  const std::int64_t give_up = monotonicNs() + 5'000'000'000;
  while ((counters.torn_reads < 3 || got < 1) && monotonicNs() < give_up) {
    if (readNext(view, next, out, nullptr, counters) != ReadOutcome::kScan) continue;
    ++got;
    if (!test::checkPattern(out, kMax).empty()) ++bad;
  }
  stop.store(true);
  writer.join();
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(counters.checksum_errors, 0u);
  // TSan runs the instrumented atomic copies nearly in turn, so tears are rare there; the Release and
  // ASan builds require them. Every build requires that no torn copy is ever returned (bad == 0).
  if (!RIGCAL_TSAN) {
    EXPECT_GE(counters.torn_reads, 1u) << "no torn copy happened: the test did not exercise the re-check";
  }
  std::printf("[ info ] got %llu, torn %llu, overruns %llu\n", static_cast<unsigned long long>(got),
              static_cast<unsigned long long>(counters.torn_reads),
              static_cast<unsigned long long>(counters.overruns));
}

TEST(Futex, WaitTimesOutAndWakeReleasesASleeper) {
  std::atomic<std::uint32_t> word{5};
  const std::int64_t t0 = monotonicNs();
  EXPECT_EQ(futexWait(word, 5, std::chrono::milliseconds(20)), FutexWait::kTimedOut);
  EXPECT_GE(monotonicNs() - t0, 15'000'000);
  EXPECT_EQ(futexWait(word, 6, std::chrono::milliseconds(20)), FutexWait::kValueChanged);
  std::thread sleeper([&] {
    while (word.load() == 5) futexWait(word, 5, std::chrono::seconds(5));
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::int64_t t1 = monotonicNs();
  word.store(6);
  futexWakeAll(word);
  sleeper.join();
  EXPECT_LT(monotonicNs() - t1, 2'000'000'000);  // woken, not timed out after 5 s
}

TEST(Liveness, TellsThisProcessFromAGoneOrRecycledPid) {
  const ProcessIdentity me = selfIdentity();
  EXPECT_GT(me.start_time, 0u);
  EXPECT_TRUE(processAlive(me));
  EXPECT_FALSE(processAlive({me.pid, me.start_time + 1}));  // same pid, other start: a recycled pid
  EXPECT_FALSE(processAlive({0x3fffffff, 1}));              // no such process
}

}  // namespace
}  // namespace rigcal::shm
