// ScanRingWriter / ScanRingReader in one process, on real POSIX shared memory: naming, ownership, takeover,
// refusal of foreign or corrupted segments, clean shutdown, allocation-free steady state.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/ring_inspect.hpp"
#include "rigcal/shm/ring_segment.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"
#include "rigcal/shm/scan_ring_writer.hpp"
#include "ring_test_support.hpp"
#include "scan_pattern.hpp"

namespace rigcal::shm {
namespace {

using namespace std::chrono_literals;

WriterOptions writerOptions(const test::UniquePrefix& prefix, std::uint32_t max_points = 1000,
                            std::uint32_t slots = 4) {
  WriterOptions o;
  o.sensor = "lidar";
  o.name_prefix = prefix.str();
  o.max_points = max_points;
  o.slot_count = slots;
  return o;
}

ReaderOptions readerOptions(const test::UniquePrefix& prefix) {
  ReaderOptions o;
  o.sensor = "lidar";
  o.name_prefix = prefix.str();
  o.start_at = ReaderOptions::StartAt::kOldest;
  o.liveness_period = 20ms;
  return o;
}

/// Bytes of a segment file, and writing them back (to fake segments left by other builds or crashes).
std::string readSegment(const std::string& name) {
  std::ifstream in(segmentPath(name), std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeSegment(const std::string& name, const std::string& bytes) {
  std::ofstream out(segmentPath(name), std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(ScanRing, NamesSegmentsAfterTheSensorUnderThePrefix) {
  EXPECT_EQ(segmentName("vls128", std::string("rigcal.")), "rigcal.vls128");
  EXPECT_THROW((void)segmentName("a/b", std::string("p.")), std::invalid_argument);
  EXPECT_THROW((void)segmentName("", std::string("p.")), std::invalid_argument);
  test::UniquePrefix prefix;
  ScanRingWriter writer(writerOptions(prefix));
  EXPECT_EQ(writer.segmentName(), prefix.str() + "lidar");
  EXPECT_TRUE(std::filesystem::exists("/dev/shm/" + writer.segmentName()));
  EXPECT_EQ(writer.epoch(), 1u);
  EXPECT_FALSE(writer.tookOver());
}

TEST(ScanRing, ExchangesScansAndUnlinksOnCleanShutdown) {
  test::UniquePrefix prefix;
  auto writer = std::make_unique<ScanRingWriter>(writerOptions(prefix));
  ScanRingReader reader(readerOptions(prefix));
  ASSERT_TRUE(reader.attached());
  EXPECT_EQ(reader.writerStatus(), WriterStatus::kAlive);
  Scan in, out;
  for (std::uint64_t s = 0; s < 3; ++s) {
    test::fillPattern(in, s, test::patternPoints(s, 1000));
    ASSERT_TRUE(writer->publish(in));
  }
  for (std::uint64_t s = 0; s < 3; ++s) {
    ASSERT_EQ(reader.read(out, 1s), ReadStatus::kScan);
    EXPECT_EQ(out.sequence, s);
    EXPECT_EQ(out.sensor_id, "lidar");
    EXPECT_EQ(test::checkPattern(out, 1000), "");
  }
  EXPECT_EQ(reader.read(out, 30ms), ReadStatus::kTimeout);
  writer.reset();
  EXPECT_TRUE(prefix.segments().empty()) << "segment left behind after a clean shutdown";
  EXPECT_EQ(reader.writerStatus(), WriterStatus::kClosed);
  EXPECT_EQ(reader.stats().scans, 3u);
}

TEST(ScanRing, ReaderOfARunningRingStartsWithTheNextScanByDefault) {
  test::UniquePrefix prefix;
  ScanRingWriter writer(writerOptions(prefix));
  Scan in, out;
  for (std::uint64_t s = 0; s < 3; ++s) {
    test::fillPattern(in, s, test::patternPoints(s, 1000));
    writer.publish(in);
  }
  ReaderOptions options = readerOptions(prefix);
  options.start_at = ReaderOptions::StartAt::kNext;
  ScanRingReader reader(options);
  EXPECT_FALSE(reader.tryRead(out));
  test::fillPattern(in, 3, test::patternPoints(3, 1000));
  writer.publish(in);
  ASSERT_TRUE(reader.tryRead(out));
  EXPECT_EQ(out.sequence, 3u);
  EXPECT_EQ(reader.stats().overruns, 0u);
}

TEST(ScanRing, QuietWriterIsStalledUntilItsNextHeartbeat) {
  test::UniquePrefix prefix;
  ScanRingWriter writer(writerOptions(prefix));
  ReaderOptions options = readerOptions(prefix);
  options.stall_after = 50ms;
  ScanRingReader reader(options);
  EXPECT_EQ(reader.writerStatus(), WriterStatus::kAlive);
  std::this_thread::sleep_for(80ms);
  EXPECT_EQ(reader.writerStatus(), WriterStatus::kStalled);
  writer.heartbeat();
  EXPECT_EQ(reader.writerStatus(), WriterStatus::kAlive);
}

TEST(ScanRing, ReaderNoticesACleanCloseWithoutWaitingForItsLivenessPeriod) {
  test::UniquePrefix prefix;
  auto writer = std::make_unique<ScanRingWriter>(writerOptions(prefix));
  ReaderOptions options = readerOptions(prefix);
  options.liveness_period = 10s;
  ScanRingReader reader(options);
  std::thread closer([&] {
    std::this_thread::sleep_for(50ms);
    writer.reset();
  });
  Scan out;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(reader.read(out, 5s), ReadStatus::kWriterGone);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s);
  closer.join();
  EXPECT_EQ(reader.writerStatus(), WriterStatus::kClosed);
  EXPECT_EQ(reader.read(out, 50ms), ReadStatus::kTimeout);  // reported once; then it waits for a new writer
}

TEST(ScanRing, OversizeScanIsDroppedAndCountedNotTruncated) {
  test::UniquePrefix prefix;
  ScanRingWriter writer(writerOptions(prefix, 100));
  Scan big;
  test::fillPattern(big, 0, 101);
  EXPECT_FALSE(writer.publish(big));
  EXPECT_EQ(writer.stats().oversize_drops, 1u);
  big.ring.pop_back();
  EXPECT_THROW(writer.publish(big), std::invalid_argument);
}

TEST(ScanRing, SecondLiveWriterIsRefusedWithOneLine) {
  test::UniquePrefix prefix;
  ScanRingWriter first(writerOptions(prefix));
  try {
    ScanRingWriter second(writerOptions(prefix));
    FAIL() << "two writers on one ring";
  } catch (const RingError& e) {
    EXPECT_EQ(e.kind(), RingError::Kind::kLiveWriter);
    const std::string msg = e.what();
    EXPECT_NE(msg.find("already has a live writer (pid " + std::to_string(::getpid()) + ")"), std::string::npos)
        << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
}

TEST(ScanRing, CorruptedHeaderIsRefusedByReaderAndWriter) {
  test::UniquePrefix prefix;
  const std::string name = prefix.str() + "lidar";
  writeSegment(name, std::string(8192, '\xab'));
  try {
    ScanRingReader reader(readerOptions(prefix));
    FAIL() << "corrupted segment accepted";
  } catch (const RingError& e) {
    EXPECT_EQ(e.kind(), RingError::Kind::kCorrupted);
    EXPECT_NE(std::string(e.what()).find("is not a rigcal scan ring"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ScanRingWriter writer(writerOptions(prefix)), RingError);
  EXPECT_FALSE(inspectRing(name).error.empty());
}

TEST(ScanRing, OtherLayoutVersionIsRefusedNamingBothVersions) {
  test::UniquePrefix prefix;
  ScanRingWriter writer(writerOptions(prefix));
  // Patch the live segment the way an older build would have written it.
  const int fd = ::shm_open(("/" + writer.segmentName()).c_str(), O_RDWR, 0);
  ASSERT_GE(fd, 0);
  void* p = ::mmap(nullptr, sizeof(RingHeader), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  ASSERT_NE(p, MAP_FAILED);
  static_cast<RingHeader*>(p)->layout_version = 99;
  ::munmap(p, sizeof(RingHeader));
  try {
    ScanRingReader reader(readerOptions(prefix));
    FAIL() << "foreign layout accepted";
  } catch (const RingError& e) {
    EXPECT_EQ(e.kind(), RingError::Kind::kLayoutMismatch);
    const std::string msg = e.what();
    EXPECT_NE(msg.find("has layout version 99"), std::string::npos) << msg;
    EXPECT_NE(msg.find("reads layout version " + std::to_string(kLayoutVersion)), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
}

TEST(ScanRing, StaleSegmentOfAnotherLayoutIsReplacedByANewWriter) {
  test::UniquePrefix prefix;
  std::string stale;
  {
    ScanRingWriter old(writerOptions(prefix));
    stale = readSegment(old.segmentName());
  }
  const std::uint32_t other_version = 99;  // left behind by a crashed build of another version
  ASSERT_GT(stale.size(), sizeof(RingHeader));
  std::memcpy(stale.data() + offsetof(RingHeader, layout_version), &other_version, sizeof other_version);
  writeSegment(prefix.str() + "lidar", stale);

  ScanRingWriter writer(writerOptions(prefix));
  EXPECT_TRUE(writer.tookOver());
  ScanRingReader reader(readerOptions(prefix));  // would throw if the old layout were still there
  Scan in, out;
  test::fillPattern(in, 1, test::patternPoints(1, 1000));
  writer.publish(in);
  ASSERT_EQ(reader.read(out, 1s), ReadStatus::kScan);
  EXPECT_EQ(test::checkPattern(out, 1000), "");
}

TEST(ScanRing, ReaderFollowsANewWriterIntoANewSegment) {
  test::UniquePrefix prefix;
  ScanRingReader reader(readerOptions(prefix));  // before any writer
  EXPECT_FALSE(reader.attached());
  EXPECT_EQ(reader.writerStatus(), WriterStatus::kAbsent);
  Scan in, out;
  {
    ScanRingWriter a(writerOptions(prefix));
    for (std::uint64_t s = 0; s < 3; ++s) {
      test::fillPattern(in, s, test::patternPoints(s, 1000));
      a.publish(in);
    }
    ASSERT_TRUE(reader.tryRead(out));  // attaches: a ring that appears later is read from its oldest scan
    EXPECT_EQ(out.sequence, 0u);
  }  // clean close: unlinked while the reader still maps it with two unread scans
  for (std::uint64_t s = 1; s < 3; ++s) {
    ASSERT_EQ(reader.read(out, 1s), ReadStatus::kScan) << s;
    EXPECT_EQ(out.sequence, s);
  }
  ScanRingWriter b(writerOptions(prefix, 2000, 6));  // another geometry, another segment
  test::fillPattern(in, 10, test::patternPoints(10, 2000));
  b.publish(in);
  ASSERT_EQ(reader.read(out, 2s), ReadStatus::kScan);
  EXPECT_EQ(out.sequence, 10u);
  EXPECT_EQ(test::checkPattern(out, 2000), "");
  EXPECT_EQ(reader.stats().reattaches, 1u);
  EXPECT_EQ(reader.writerStatus(), WriterStatus::kAlive);
}

TEST(ScanRing, SteadyStatePublishAndReadDoNotAllocate) {
  RIGCAL_REQUIRE_ALLOCATION_COUNTING();
  test::UniquePrefix prefix;
  ScanRingWriter writer(writerOptions(prefix, 5000, 4));
  ScanRingReader reader(readerOptions(prefix));
  Scan in, out;
  ScanMeta meta;
  test::fillPattern(in, 0, 5000);
  for (int warm = 0; warm < 2; ++warm) {  // out grows to the largest scan once
    writer.publish(in);
    ASSERT_EQ(reader.read(out, 1s, &meta), ReadStatus::kScan);
  }
  test::AllocationCounter::start();
  for (int i = 0; i < 50; ++i) {
    in.sequence = static_cast<std::uint64_t>(i);
    writer.publish(in);
    if (reader.read(out, 1s, &meta) != ReadStatus::kScan) break;
  }
  EXPECT_EQ(reader.read(out, 5ms), ReadStatus::kTimeout);  // the idle path (futex wait) too
  const std::uint64_t allocations = test::AllocationCounter::stop();
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(reader.stats().scans, 52u);
}

TEST(ScanRing, InspectShowsWriterReadersAndCounters) {
  test::UniquePrefix prefix;
  ScanRingWriter writer(writerOptions(prefix, 1000, 4));
  ScanRingReader reader(readerOptions(prefix));
  Scan in, out;
  for (std::uint64_t s = 0; s < 6; ++s) {  // the reader is lapped: 2 overruns
    test::fillPattern(in, s, test::patternPoints(s, 1000));
    writer.publish(in);
  }
  ASSERT_EQ(reader.read(out, 1s), ReadStatus::kScan);
  const RingInfo info = inspectRing(writer.segmentName());
  EXPECT_TRUE(info.present);
  EXPECT_EQ(info.error, "");
  EXPECT_EQ(info.sensor, "lidar");
  EXPECT_EQ(info.writer, WriterStatus::kAlive);
  EXPECT_EQ(info.writer_pid, ::getpid());
  EXPECT_EQ(info.write_index, 6u);
  EXPECT_EQ(info.readers, 1u);
  EXPECT_EQ(info.overruns, 2u);
  EXPECT_EQ(info.max_backlog, 3u);
  EXPECT_EQ(info.last_stamp_ns, in.stamp_ns);
  EXPECT_FALSE(inspectRing(prefix.str() + "nothing").present);
}

}  // namespace
}  // namespace rigcal::shm
