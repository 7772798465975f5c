// Issue 18, the reader side of the shared-memory rings: readers (the library, `rigcal monitor`,
// `rigcal map --shm`) apply the writer's rule before mapping a ring — refuse one another user owns or other
// users may write — and a ring truncated under a reading process is reported, not a SIGBUS.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/ring_segment.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"
#include "ring_test_support.hpp"
#include "sanitizers.hpp"
#include "subprocess.hpp"
#include "test_data.hpp"

namespace rigcal::shm {
namespace {

using namespace std::chrono_literals;
using test::Subprocess;

/// The kForeign message a reader of `prefix`+`sensor` gives, or "" if it attached or waited without one.
std::string readerRefusal(const test::UniquePrefix& prefix, const std::string& sensor) {
  ReaderOptions options;
  options.sensor = sensor;
  options.name_prefix = prefix.str();
  try {
    ScanRingReader reader(options);
    Scan scan;
    (void)reader.read(scan, 200ms);
  } catch (const RingError& e) {
    EXPECT_EQ(e.kind(), RingError::Kind::kForeign) << e.what();
    return e.what();
  }
  return {};
}

TEST(RingReaderTrust, ARingOthersMayWriteIsRefusedByEveryReader) {
  test::UniquePrefix prefix;
  const std::filesystem::path ring = segmentPath(prefix.str() + "top");
  { std::ofstream(ring) << ""; }  // pre-created, empty, as a hijacker would
  ASSERT_EQ(::chmod(ring.c_str(), 0666), 0);

  const std::string refusal = readerRefusal(prefix, "top");
  EXPECT_NE(refusal.find("has mode 0666"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find(prefix.str() + "top"), std::string::npos) << "names the ring: " << refusal;

  Subprocess monitor({rigcal::test::rigcalBinary().string(), "monitor", "--once", "--interval", "0.2"},
                     {"RIGCAL_SHM_PREFIX=" + prefix.str()});
  EXPECT_EQ(monitor.wait(10s), 0) << monitor.errText();
  std::string table;
  for (const auto& l : monitor.lines()) table += l + "\n";
  EXPECT_NE(table.find("has mode 0666"), std::string::npos) << table;

  Subprocess map({rigcal::test::rigcalBinary().string(), "map", "--config",
                  std::string(RIGCAL_RIGS_DIR) + "/velodyne-car.yaml", "--shm", "--shm-prefix", prefix.str()});
  const auto code = map.wait(20s);
  EXPECT_TRUE(code && *code != 0 && *code < 128) << "map --shm must refuse, not wait or crash";
  EXPECT_NE(map.errText().find("has mode 0666"), std::string::npos) << map.errText();
  EXPECT_EQ(std::filesystem::file_size(ring), 0u) << "a reader never writes a refused ring";
}

TEST(RingReaderTrust, ARingOfAnotherUserIsRefused) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to create a segment owned by another user";
  test::UniquePrefix prefix;
  const std::filesystem::path ring = segmentPath(prefix.str() + "top");
  { std::ofstream(ring) << ""; }
  ASSERT_EQ(::chmod(ring.c_str(), 0600), 0);
  ASSERT_EQ(::chown(ring.c_str(), 65534, 65534), 0);
  const std::string refusal = readerRefusal(prefix, "top");
  EXPECT_NE(refusal.find("belongs to uid 65534"), std::string::npos) << refusal;
}

// A peer process truncates a live ring (ftruncate) while a reader process waits on it and reads: the reader
// reports the truncation naming the ring and exits through its error path, not through SIGBUS.
TEST(RingReaderTrust, ARingTruncatedUnderAReaderIsReportedNotASigbus) {
  test::UniquePrefix prefix;
  Subprocess writer({test::peerPath(), "writer", "--prefix", prefix.str(), "--sensor", "lidar", "--points", "2000",
                     "--slots", "8", "--count", "100000", "--rate", "50"});
  ASSERT_TRUE(writer.waitForLine("ready", 5s)) << writer.errText();
  Subprocess reader({test::peerPath(), "reader", "--prefix", prefix.str(), "--sensor", "lidar", "--points", "2000",
                     "--timeout-ms", "20000"});
  ASSERT_TRUE(reader.waitForLine("status=alive", 5s)) << reader.errText();
  std::this_thread::sleep_for(200ms);  // a few scans read (small ones: the copy out of a slot takes ~µs)

  const std::filesystem::path ring = segmentPath(prefix.str() + "lidar");
  const auto full = std::filesystem::file_size(ring);
  ASSERT_EQ(::truncate(ring.c_str(), 0), 0);  // header and slots gone: the next touch of any page is a SIGBUS

  const auto code = reader.wait(10s);
  ASSERT_TRUE(code) << "the reader neither reported nor exited";
  EXPECT_NE(*code, 128 + SIGBUS) << "the reader died of SIGBUS";
  EXPECT_EQ(*code, 3) << "ring_peer's RingError exit; stderr: " << reader.errText();
  EXPECT_NE(reader.errText().find("'" + prefix.str() + "lidar' was truncated to 0 of its " + std::to_string(full)),
            std::string::npos)
      << reader.errText();
  writer.kill(SIGKILL);  // the writer side of a truncated ring is the driver's business, not this test's
  (void)writer.wait(2s);
}


// The same while the reader is busy copying big slots (a 400k-point scan takes milliseconds to copy): the
// truncation lands in the middle of a copy more often than not, after the size check that precedes each
// read. The truncation shield (zero pages in place of the lost ones) lets the next check report it like
// any other truncation; no trial may die of SIGBUS.
TEST(RingReaderTrust, ARingTruncatedDuringACopyIsReportedNotASigbus) {
  int mid_copy = 0;
  const int trials = rigcal::test::kSanitized ? 2 : 6;
  for (int trial = 0; trial < trials; ++trial) {
    test::UniquePrefix prefix;
    Subprocess writer({test::peerPath(), "writer", "--prefix", prefix.str(), "--sensor", "lidar", "--points",
                       "400000", "--slots", "4", "--count", "100000", "--rate", "200"});
    ASSERT_TRUE(writer.waitForLine("ready", 10s)) << writer.errText();
    Subprocess reader({test::peerPath(), "reader", "--prefix", prefix.str(), "--sensor", "lidar", "--points",
                       "400000", "--timeout-ms", "20000"});
    ASSERT_TRUE(reader.waitForLine("status=alive", 10s)) << reader.errText();
    std::this_thread::sleep_for(std::chrono::milliseconds(150 + 37 * trial));
    const std::filesystem::path ring = segmentPath(prefix.str() + "lidar");
    Subprocess truncate({"/usr/bin/truncate", "-s", "0", ring.string()});  // a real second process cuts it
    ASSERT_EQ(truncate.wait(10s), 0) << truncate.errText();
    const auto code = reader.wait(20s);
    ASSERT_TRUE(code) << "the reader neither reported nor exited";
    EXPECT_NE(*code, 128 + SIGBUS) << "trial " << trial << ": the reader died of SIGBUS";
    EXPECT_EQ(*code, 3) << "trial " << trial << ": " << reader.errText();
    EXPECT_NE(reader.errText().find("'" + prefix.str() + "lidar' was truncated to 0 of its"), std::string::npos)
        << reader.errText();
    if (reader.errText().find("SIGBUS caught") != std::string::npos) ++mid_copy;  // after the size check
    writer.kill(SIGKILL);
    (void)writer.wait(2s);
  }
  std::printf("truncations that landed after the size check (SIGBUS caught, zero pages): %d of %d\n", mid_copy, trials);
}

}  // namespace
}  // namespace rigcal::shm
