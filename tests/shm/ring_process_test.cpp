// Writers and readers in separate processes on real shared memory, killed with SIGKILL at bad moments.
// Each reader process checks every value of every scan it gets (scan_pattern.hpp) and reports a summary.
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <thread>

#include "sanitizers.hpp"
#include "rigcal/shm/ring_layout.hpp"
#include "rigcal/shm/ring_segment.hpp"
#include "ring_test_support.hpp"
#include "subprocess.hpp"

namespace rigcal::shm {
namespace {

using namespace std::chrono_literals;
using test::intField;
using test::Subprocess;

std::unique_ptr<Subprocess> peer(const std::string& mode, const test::UniquePrefix& prefix,
                                 std::vector<std::string> args) {
  std::vector<std::string> argv = {test::peerPath(), mode, "--prefix", prefix.str(), "--sensor", "lidar"};
  argv.insert(argv.end(), args.begin(), args.end());
  return std::make_unique<Subprocess>(argv);
}

/// Waits for the reader's summary and its exit; returns the summary line.
std::string summaryOf(Subprocess& reader, std::chrono::milliseconds timeout = 9s) {
  const auto line = reader.waitForLine("summary", timeout);
  EXPECT_TRUE(line) << "reader gave no summary; stderr: " << reader.errText();
  EXPECT_EQ(reader.wait(2s), 0) << (line ? *line : "") << " stderr: " << reader.errText();
  if (line) std::printf("[ info ] %s\n", line->c_str());
  return line.value_or("");
}

TEST(RingProcesses, WriterAndThreeReadersExchangeScansIntact) {
  test::UniquePrefix prefix;
  auto writer = peer("writer", prefix, {"--points", "10000", "--slots", "8", "--count", "60", "--rate", "100",
                                        "--wait-readers", "3"});
  ASSERT_TRUE(writer->waitForLine("ready", 5s)) << writer->errText();
  std::vector<std::unique_ptr<Subprocess>> readers;
  for (int i = 0; i < 3; ++i) {
    readers.push_back(peer("reader", prefix, {"--points", "10000", "--count", "60", "--oldest"}));
  }
  for (auto& r : readers) {
    const std::string s = summaryOf(*r);
    EXPECT_EQ(intField(s, "good"), 60) << s;
    EXPECT_EQ(intField(s, "bad"), 0) << s;
    EXPECT_EQ(intField(s, "overruns"), 0) << s;
    EXPECT_EQ(intField(s, "checksum_errors"), 0) << s;
    EXPECT_EQ(intField(s, "first_seq"), 0) << s;
    EXPECT_EQ(intField(s, "last_seq"), 59) << s;
  }
  ASSERT_EQ(writer->wait(5s), 0) << writer->errText();
  EXPECT_TRUE(prefix.segments().empty()) << "segment left behind after a clean shutdown";
}

TEST(RingProcesses, WriterKilledMidWriteIsReportedDeadAndANewWriterResumes) {
  test::UniquePrefix prefix;
  auto reader = peer("reader", prefix, {"--points", "20000", "--count", "30", "--oldest"});
  ASSERT_TRUE(reader->waitForLine("started", 5s)) << reader->errText();
  auto a = peer("writer", prefix, {"--points", "20000", "--slots", "8", "--count", "100", "--rate", "100",
                                   "--wait-readers", "1", "--stall-after", "10"});
  ASSERT_TRUE(a->waitForLine("midwrite", 5s)) << a->errText();
  a->kill(SIGKILL);  // slot counter odd, half the slot overwritten
  EXPECT_EQ(a->wait(2s), 128 + SIGKILL);
  ASSERT_TRUE(reader->waitForLine("status=dead", 3s)) << "reader did not notice the dead writer";
  EXPECT_EQ(prefix.segments().size(), 1u) << "the killed writer's segment should still be there";

  auto b = peer("writer", prefix, {"--points", "20000", "--slots", "8", "--count", "20", "--rate", "100",
                                   "--first-seq", "1000", "--wait-readers", "1"});
  const auto ready = b->waitForLine("ready", 5s);
  ASSERT_TRUE(ready) << b->errText();
  EXPECT_EQ(intField(*ready, "took_over"), 1) << *ready;  // the stale segment was reclaimed
  EXPECT_EQ(intField(*ready, "epoch"), 2) << *ready;

  const std::string s = summaryOf(*reader);
  EXPECT_EQ(intField(s, "good"), 30) << s;  // 10 from the dead writer, 20 from the new one
  EXPECT_EQ(intField(s, "bad"), 0) << s;
  EXPECT_EQ(intField(s, "dead_seen"), 1) << s;
  EXPECT_GE(intField(s, "restarts"), 1) << s;
  EXPECT_EQ(intField(s, "last_seq"), 1019) << s;
  EXPECT_EQ(test::field(s, "epochs"), "1,2") << s;
  EXPECT_EQ(b->wait(5s), 0) << b->errText();
  EXPECT_TRUE(prefix.segments().empty());
}

TEST(RingProcesses, WriterKilledAtRandomMomentsNeverYieldsATornScan) {
  test::UniquePrefix prefix;
  auto reader = peer("reader", prefix, {"--points", "60000", "--oldest", "--until-closed"});
  ASSERT_TRUE(reader->waitForLine("started", 5s));
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> pause_ms(80, 250);
  constexpr int kKills = 4;
  for (int i = 0; i < kKills; ++i) {
    // As fast as it can: most of its time is spent copying into a slot, so most kills land mid-write.
    auto w = peer("writer", prefix, {"--points", "60000", "--slots", "4", "--count", "1000000",
                                     "--first-seq", std::to_string(i * 1'000'000)});
    const auto ready = w->waitForLine("ready", 5s);
    ASSERT_TRUE(ready) << w->errText();
    EXPECT_EQ(intField(*ready, "epoch"), i + 1) << *ready;
    std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms(rng)));
    w->kill(SIGKILL);
    EXPECT_EQ(w->wait(2s), 128 + SIGKILL);
  }
  auto last = peer("writer", prefix, {"--points", "60000", "--slots", "4", "--count", "10", "--rate", "100",
                                      "--first-seq", "9000000"});
  EXPECT_EQ(last->wait(5s), 0) << last->errText();
  const std::string s = summaryOf(*reader);
  EXPECT_GT(intField(s, "good"), 0) << s;
  EXPECT_EQ(intField(s, "bad"), 0) << s;
  EXPECT_EQ(intField(s, "checksum_errors"), 0) << s;
  EXPECT_GE(intField(s, "restarts"), 1) << s;
  EXPECT_EQ(intField(s, "last_seq"), 9000009) << s;
  EXPECT_TRUE(prefix.segments().empty());
}

TEST(RingProcesses, KilledReadersDoNotAffectTheWriter) {
  test::UniquePrefix prefix;
  auto writer = peer("writer", prefix, {"--points", "5000", "--slots", "8", "--count", "150", "--rate", "100",
                                        "--start-delay-ms", "300"});
  ASSERT_TRUE(writer->waitForLine("ready", 5s));
  auto steady = peer("reader", prefix, {"--points", "5000", "--count", "150", "--oldest"});
  auto victim1 = peer("reader", prefix, {"--points", "5000", "--oldest"});
  auto victim2 = peer("reader", prefix, {"--points", "5000", "--oldest"});
  std::this_thread::sleep_for(500ms);
  victim1->kill(SIGKILL);  // most likely asleep in FUTEX_WAIT
  std::this_thread::sleep_for(300ms);
  victim2->kill(SIGKILL);  // possibly mid-copy
  EXPECT_EQ(victim1->wait(2s), 128 + SIGKILL);
  EXPECT_EQ(victim2->wait(2s), 128 + SIGKILL);
  const auto published = writer->waitForLine("published", 6s);
  ASSERT_TRUE(published) << writer->errText();
  EXPECT_EQ(intField(*published, "n"), 150);
  // 150 scans at 100 Hz take 1.49 s; a writer that waited for its dead readers would never finish. (The
  // margin is for sanitizer builds on a loaded 2-core machine, where generating a scan takes milliseconds.)
  if (rigcal::test::kWallClockAsserted) { EXPECT_LT(intField(*published, "elapsed_ms"), 3000) << *published; }
  EXPECT_EQ(writer->wait(3s), 0);
  const std::string s = summaryOf(*steady);
  EXPECT_EQ(intField(s, "bad"), 0) << s;
  EXPECT_EQ(intField(s, "good") + intField(s, "overruns"), 150) << s;  // all 150 usually; fewer only if starved
  EXPECT_EQ(intField(s, "last_seq"), 149) << s;
}

TEST(RingProcesses, SlowReaderCountsOverrunsAndGetsOnlyIntactScans) {
  test::UniquePrefix prefix;
  auto writer = peer("writer", prefix, {"--points", "10000", "--slots", "4", "--count", "100", "--rate", "200",
                                        "--start-delay-ms", "500"});
  ASSERT_TRUE(writer->waitForLine("ready", 5s));
  auto reader = peer("reader", prefix, {"--points", "10000", "--oldest", "--delay-ms", "20", "--until-closed"});
  const std::string s = summaryOf(*reader);
  EXPECT_EQ(intField(s, "bad"), 0) << s;
  EXPECT_GT(intField(s, "overruns"), 0) << s;
  EXPECT_EQ(intField(s, "checksum_errors"), 0) << s;
  EXPECT_EQ(intField(s, "good") + intField(s, "overruns"), 100) << s;  // every scan delivered or counted
  EXPECT_EQ(intField(s, "last_seq"), 99) << s;
  EXPECT_EQ(writer->wait(3s), 0);
}

TEST(RingProcesses, CorruptedHeaderAndSecondWriterAreRefusedWithOneLine) {
  test::UniquePrefix prefix;
  {
    std::ofstream out(segmentPath(prefix.str() + "lidar"), std::ios::binary);
    out << std::string(8192, '\x5a');
  }
  for (const char* mode : {"reader", "writer"}) {
    auto p = peer(mode, prefix, {"--points", "1000", "--timeout-ms", "500"});
    EXPECT_EQ(p->wait(5s), 3) << mode;
    const std::string err = p->errText();
    EXPECT_NE(err.find("is not a rigcal scan ring"), std::string::npos) << mode << ": " << err;
    EXPECT_EQ(err.find('\n'), err.size() - 1) << "not one line: " << err;
  }
  removeSegment(prefix.str() + "lidar");

  auto first = peer("writer", prefix, {"--points", "1000", "--count", "1", "--hold"});
  ASSERT_TRUE(first->waitForLine("holding", 5s));
  auto second = peer("writer", prefix, {"--points", "1000", "--count", "1"});
  EXPECT_EQ(second->wait(5s), 3);
  EXPECT_NE(second->errText().find("already has a live writer (pid " + std::to_string(first->pid()) + ")"),
            std::string::npos)
      << second->errText();
}

}  // namespace
}  // namespace rigcal::shm
