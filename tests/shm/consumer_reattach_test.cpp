// Issue 18: `rigcal map --shm` (the pipeline's ring readers, as `calibrate --shm`) follows a writer that
// dies and is restarted, reports the gap per sensor, and ends with a message once every writer is gone —
// or keeps waiting with --wait-for-writers. Real processes: ring_peer writers killed with SIGKILL.
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <memory>
#include <thread>

#include "rigcal/shm/ring_inspect.hpp"
#include "ring_test_support.hpp"
#include "sanitizers.hpp"
#include "subprocess.hpp"
#include "test_data.hpp"

namespace rigcal::shm {
namespace {

using namespace std::chrono_literals;
using test::Subprocess;

std::unique_ptr<Subprocess> writer(const test::UniquePrefix& prefix, const std::string& sensor, int first_seq = 0) {
  auto w = std::make_unique<Subprocess>(std::vector<std::string>{
      test::peerPath(), "writer", "--prefix", prefix.str(), "--sensor", sensor, "--points", "2000", "--count",
      "100000", "--rate", "20", "--first-seq", std::to_string(first_seq)});
  EXPECT_TRUE(w->waitForLine("ready", 5s)) << w->errText();
  return w;
}

std::unique_ptr<Subprocess> mapOverShm(const test::UniquePrefix& prefix, std::vector<std::string> extra = {}) {
  std::vector<std::string> argv = {rigcal::test::rigcalBinary().string(), "map", "--config",
                                   std::string(RIGCAL_RIGS_DIR) + "/velodyne-car.yaml", "--shm", "--shm-prefix",
                                   prefix.str()};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return std::make_unique<Subprocess>(argv);
}

void kill(std::unique_ptr<Subprocess>& p) {
  p->kill(SIGKILL);
  EXPECT_EQ(p->wait(2s), 128 + SIGKILL);
}

/// Lets `map` run for `d`, draining its output (wait() pumps the pipes); false if it exited meanwhile.
bool runsFor(Subprocess& map, std::chrono::milliseconds d) { return !map.wait(d).has_value(); }

// Conditions, not fixed sleeps: the lead's suite (or a sanitizer build) may slow every process down.
constexpr auto kPatience = std::chrono::seconds(rigcal::test::kSanitized ? 60 : 15);

/// Runs `map` until a reader holds a record in each ring of `sensors` and has read for a while.
bool readingAll(Subprocess& map, const test::UniquePrefix& prefix, const std::vector<std::string>& sensors) {
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  for (;;) {
    bool all = true;
    for (const auto& s : sensors) all = all && inspectRing(prefix.str() + s).readers > 0;
    if (all) return runsFor(map, 500ms);  // ten scans at 20 Hz
    if (!runsFor(map, 100ms) || std::chrono::steady_clock::now() > deadline) return false;
  }
}

/// Runs `map` until its stderr holds `text`; false if it exits or the patience runs out first.
bool untilSaid(Subprocess& map, const std::string& text) {
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (map.errText().find(text) == std::string::npos) {
    if (!runsFor(map, 100ms) || std::chrono::steady_clock::now() > deadline) return false;
  }
  return true;
}

TEST(ConsumerReattach, FollowsARestartedWriterReportsTheGapAndEndsWhenEveryWriterIsGone) {
  test::UniquePrefix prefix;
  auto top = writer(prefix, "top");
  auto left = writer(prefix, "front_left");
  auto map = mapOverShm(prefix);
  ASSERT_TRUE(readingAll(*map, prefix, {"top", "front_left"})) << map->errText();

  kill(left);  // the driver of one calibration lidar dies...
  ASSERT_TRUE(untilSaid(*map, "warning: sensor 'front_left': the writer of its ring is dead")) << map->errText();
  left = writer(prefix, "front_left", 1000);  // ...and is restarted
  ASSERT_TRUE(untilSaid(*map, "warning: sensor 'front_left': a new writer (epoch ")) << map->errText();
  const std::string err = map->errText();
  EXPECT_NE(err.find("s without scans"), std::string::npos) << err;
  EXPECT_EQ(err.find("sensor 'top'"), std::string::npos) << "its writer never stopped: " << err;
  EXPECT_EQ(err.find("every ring writer is gone"), std::string::npos) << err;

  kill(top);
  kill(left);
  const auto code = map->wait(kPatience);
  ASSERT_TRUE(code) << "map --shm kept waiting with every writer gone: " << map->errText();
  EXPECT_LT(*code, 128) << "no crash: " << map->errText();
  EXPECT_NE(map->errText().find("every ring writer is gone: input ends"), std::string::npos) << map->errText();
  EXPECT_EQ(map->errText().find("front_right"), std::string::npos) << "it never had a writer: " << map->errText();
}

TEST(ConsumerReattach, WaitForWritersKeepsWaitingForANewWriter) {
  test::UniquePrefix prefix;
  auto top = writer(prefix, "top");
  auto map = mapOverShm(prefix, {"--wait-for-writers"});
  ASSERT_TRUE(readingAll(*map, prefix, {"top"})) << map->errText();
  kill(top);
  ASSERT_TRUE(untilSaid(*map, "warning: sensor 'top': the writer of its ring is dead")) << map->errText();
  ASSERT_TRUE(runsFor(*map, 1000ms)) << "--wait-for-writers keeps waiting: " << map->errText();
  top = writer(prefix, "top", 1000);
  ASSERT_TRUE(untilSaid(*map, "warning: sensor 'top': a new writer (epoch ")) << map->errText();
  map->kill(SIGINT);
  const auto code = map->wait(kPatience);
  ASSERT_TRUE(code) << map->errText();
  EXPECT_LT(*code, 128) << map->errText();
  EXPECT_EQ(map->errText().find("every ring writer is gone"), std::string::npos) << map->errText();
}

}  // namespace
}  // namespace rigcal::shm
