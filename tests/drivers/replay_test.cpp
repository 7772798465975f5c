// Live path end to end: real captures replayed over loopback UDP (PcapReplayer in a thread, or the
// `rigcal replay` binary) into UdpSource must arrive byte-identical and in the order PcapSource reads
// them, with the recorded timing. Every datagram goes to 127.0.0.1 on an ephemeral port.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <map>
#include <set>
#include <thread>
#include <vector>

#include "sanitizers.hpp"
#include "rigcal/drivers/pcap_replayer.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/udp_source.hpp"
#include "test_data.hpp"

extern char** environ;

namespace rigcal::drivers {
namespace {

using rigcal::test::fileContents;

using Clock = std::chrono::steady_clock;
using Bytes = std::vector<std::uint8_t>;

struct Datagram {
  Bytes payload;
  TimeNs time = 0;
  UdpEndpoint source;
};

std::vector<Datagram> readCapture(const std::filesystem::path& file, std::uint16_t port) {
  std::vector<Datagram> out;
  PcapSource source(file, PacketFilter{port, std::nullopt});
  while (auto p = source.next()) out.push_back({Bytes(p->payload.begin(), p->payload.end()), p->receive_ns, p->source});
  return out;
}

UdpSourceConfig listenerConfig() {
  UdpSourceConfig c;
  c.bind_address = "127.0.0.1";
  c.port = 0;
  c.timeout = std::chrono::milliseconds(300);
  return c;
}

// Drains `source` into `out` until `done` was already set before a next() that found nothing.
void drain(UdpSource& source, const std::atomic<bool>& done, std::vector<Datagram>& out) {
  while (true) {
    const bool finished = done.load();
    auto p = source.next();
    if (p)
      out.push_back({Bytes(p->payload.begin(), p->payload.end()), p->receive_ns, p->source});
    else if (finished)
      return;
  }
}

/// Drains `source` into `received` on its own thread until stop(), which the destructor also calls: a test
/// that fails or throws before stopping it (RIGCAL_BIN unset outside ctest) ends cleanly instead of
/// destroying a joinable thread (std::terminate).
class BackgroundDrain {
 public:
  BackgroundDrain(UdpSource& source, std::vector<Datagram>& received)
      : thread_([this, &source, &received] { drain(source, done_, received); }) {}
  ~BackgroundDrain() { stop(); }
  BackgroundDrain(const BackgroundDrain&) = delete;
  BackgroundDrain& operator=(const BackgroundDrain&) = delete;
  /// Reads what is still queued, then returns.
  void stop() {
    done_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::atomic<bool> done_{false};
  std::thread thread_;
};

struct LiveRun {
  std::vector<Datagram> received;
  SourceStats source_stats;
  ReplayStats replay;
};

// Replays `file` (datagrams to `port` only) at `rate` into a UdpSource on an ephemeral loopback port.
LiveRun replayInProcess(const std::filesystem::path& file, std::uint16_t port, double rate) {
  LiveRun run;
  UdpSource source(listenerConfig());
  ReplayConfig config;
  config.rate = rate;
  config.filter.destination_port = port;
  config.port_offset = int(source.port()) - int(port);
  PcapReplayer replayer(file, config);
  std::atomic<bool> done{false};
  std::thread sender([&] {
    run.replay = replayer.run();
    done = true;
  });
  drain(source, done, run.received);
  sender.join();
  source.refreshKernelDrops();
  run.source_stats = source.stats();
  return run;
}

void expectSameDatagramsInOrder(const std::vector<Datagram>& received, const std::vector<Datagram>& expected) {
  ASSERT_EQ(received.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
    ASSERT_EQ(received[i].payload, expected[i].payload) << "datagram " << i << " differs";
}

void expectIncreasingTimes(const std::vector<Datagram>& received) {
  for (std::size_t i = 1; i < received.size(); ++i)
    ASSERT_GT(received[i].time, received[i - 1].time) << "receive time of datagram " << i;
}

TEST(LiveReplay, VelodyneCaptureArrivesByteIdenticalInOrderAtTheRecordedRate) {
  RIGCAL_REQUIRE_DATA(file, "velodyne/vlp16_dual.pcap");
  const auto expected = readCapture(file, 2368);
  ASSERT_GT(expected.size(), 500u);
  const LiveRun run = replayInProcess(file, 2368, 1.0);
  expectSameDatagramsInOrder(run.received, expected);
  expectIncreasingTimes(run.received);
  EXPECT_EQ(run.source_stats.kernel_drops, 0u);
  EXPECT_EQ(run.replay.packets, expected.size());
  EXPECT_EQ(run.replay.send_errors, 0u);
  const TimeNs span = expected.back().time - expected.front().time;
  const TimeNs received_span = run.received.back().time - run.received.front().time;
  std::cout << "capture span " << toSeconds(span) << " s, received span " << toSeconds(received_span)
            << " s, late " << run.replay.late_packets << " (max " << double(run.replay.max_lateness_ns) / 1e6
            << " ms)\n";
  EXPECT_NEAR(toSeconds(received_span), toSeconds(span), 0.05);
}

TEST(LiveReplay, OusterDatagramsLargerThanTheMtuArriveWhole) {
  RIGCAL_REQUIRE_DATA(file, "ouster/OS-1-32-G_v2.1.1_1024x10.pcap");
  const auto expected = readCapture(file, 7502);
  ASSERT_EQ(expected.size(), 64u);
  ASSERT_GT(expected.front().payload.size(), 1500u);
  const LiveRun run = replayInProcess(file, 7502, 1.0);
  expectSameDatagramsInOrder(run.received, expected);
  expectIncreasingTimes(run.received);
  EXPECT_EQ(run.source_stats.kernel_drops, 0u);
  EXPECT_EQ(run.source_stats.malformed, 0u);
}

TEST(LiveReplay, TwoSensorsOnOnePortKeepDistinctSourcePorts) {
  RIGCAL_REQUIRE_DATA(file, "ouster/same_ports.pcap");
  const auto expected = readCapture(file, 7502);
  const LiveRun run = replayInProcess(file, 7502, 1.0);
  ASSERT_EQ(run.received.size(), expected.size());
  // Each original source endpoint (address, port) maps to one sending port, in both directions.
  using Endpoint = std::pair<std::uint32_t, std::uint16_t>;
  std::map<Endpoint, std::uint16_t> port_of;
  std::map<std::uint16_t, Endpoint> endpoint_of;
  std::set<std::uint32_t> addresses;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const Endpoint original{expected[i].source.address, expected[i].source.port};
    addresses.insert(original.first);
    const auto [a, inserted_a] = port_of.emplace(original, run.received[i].source.port);
    const auto [b, inserted_b] = endpoint_of.emplace(run.received[i].source.port, original);
    EXPECT_EQ(a->second, run.received[i].source.port) << "datagram " << i;
    EXPECT_EQ(b->second, original) << "datagram " << i;
    EXPECT_EQ(run.received[i].payload, expected[i].payload) << "datagram " << i;
  }
  EXPECT_EQ(addresses.size(), 2u) << "two sensors";
  EXPECT_EQ(run.replay.sockets, port_of.size());
  EXPECT_EQ(endpoint_of.size(), port_of.size());
}

TEST(LiveReplay, MaxRateIgnoresTheRecordedTiming) {
  RIGCAL_REQUIRE_DATA(file, "velodyne/vlp16_20hz_veloview.pcap");
  const auto expected = readCapture(file, 2368);
  const TimeNs span = expected.back().time - expected.front().time;
  const LiveRun run = replayInProcess(file, 2368, 0.0);
  if (rigcal::test::kWallClockAsserted) { EXPECT_LT(run.replay.duration_ns, span / 4); }
  EXPECT_EQ(run.replay.late_packets, 0u);
  // Without pacing the receiver may fall behind; what arrived is still in order and counted.
  EXPECT_EQ(run.received.size() + run.source_stats.kernel_drops, expected.size());
}

TEST(LiveReplay, RefusesATargetOutsideLoopback) {
  RIGCAL_REQUIRE_DATA(file, "velodyne/vlp16_dual.pcap");
  ReplayConfig config;
  config.target_address = 0xC0000201;  // 192.0.2.1: the constructor refuses before any socket exists
  try {
    PcapReplayer replayer(file, config);
    FAIL() << "a remote target needs allow_remote";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--allow-remote"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(PcapReplayer::isLoopback(0x7f0000fe));
  EXPECT_FALSE(PcapReplayer::isLoopback(0x80000001));
}

TEST(LiveReplay, APortOffsetThatLeavesThePortRangeIsAnError) {
  RIGCAL_REQUIRE_DATA(file, "velodyne/vlp16_dual.pcap");
  ReplayConfig config;
  config.rate = 0;
  config.port_offset = 65000;
  PcapReplayer replayer(file, config);
  EXPECT_THROW(replayer.run(), std::invalid_argument);
}

// --- the rigcal binary ---------------------------------------------------------------------------

struct Child {
  pid_t pid = -1;
  std::filesystem::path out, err;
};

Child spawnRigcal(const test::TempDir& dir, const std::vector<std::string>& args) {
  Child c;
  c.out = dir / "stdout.txt";
  c.err = dir / "stderr.txt";
  const std::string bin = test::rigcalBinary().string();
  std::vector<char*> argv{const_cast<char*>(bin.c_str())};
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, c.out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, c.err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int rc = posix_spawn(&c.pid, bin.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  EXPECT_EQ(rc, 0) << "cannot start " << bin;
  return c;
}

int waitExit(const Child& c) {
  int status = 0;
  waitpid(c.pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

TEST(ReplayCommand, RateOneTakesAboutTheCaptureDuration) {
  RIGCAL_REQUIRE_DATA(file, "velodyne/vlp16_20hz_veloview.pcap");
  const auto expected = readCapture(file, 2368);
  const TimeNs span = expected.back().time - expected.front().time;
  ASSERT_GT(span, 2 * kNsPerSec);
  UdpSource listener(listenerConfig());
  std::vector<Datagram> received;
  BackgroundDrain reader(listener, received);
  test::TempDir dir;
  const auto t0 = Clock::now();
  const Child child = spawnRigcal(dir, {"replay", file.string(), "--to", "127.0.0.1", "--rate", "1.0", "--port",
                                        "2368", "--port-offset", std::to_string(int(listener.port()) - 2368)});
  const int code = waitExit(child);
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  reader.stop();
  const std::string out = fileContents(child.out);
  ASSERT_EQ(code, 0) << out << fileContents(child.err);
  EXPECT_NE(out.find("replayed " + std::to_string(expected.size()) + " packets"), std::string::npos) << out;
  std::cout << out << "wall " << wall << " s for a capture span of " << toSeconds(span) << " s\n";
  EXPECT_GE(wall, toSeconds(span));
  // Process start-up and file opening included.
  if (rigcal::test::kWallClockAsserted) { EXPECT_LT(wall, toSeconds(span) + 0.75); }

  expectSameDatagramsInOrder(received, expected);
  expectIncreasingTimes(received);
  listener.refreshKernelDrops();
  EXPECT_EQ(listener.stats().kernel_drops, 0u);
  const TimeNs received_span = received.back().time - received.front().time;
  std::cout << "received span " << toSeconds(received_span) << " s (kernel receive stamps)\n";
  EXPECT_NEAR(toSeconds(received_span), toSeconds(span), 0.05) << "inter-packet timing preserved";
}

TEST(ReplayCommand, LoopRunsUntilInterruptedAndSummarises) {
  RIGCAL_REQUIRE_DATA(file, "ouster/OS-1-32-G_v2.1.1_1024x10.pcap");  // 0.1 s per pass
  UdpSource listener(listenerConfig());
  std::vector<Datagram> received;
  BackgroundDrain reader(listener, received);
  test::TempDir dir;
  const Child child = spawnRigcal(dir, {"replay", file.string(), "--to", "127.0.0.1", "--loop", "--port", "7502",
                                        "--port-offset", std::to_string(int(listener.port()) - 7502)});
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  kill(child.pid, SIGINT);
  const int code = waitExit(child);
  reader.stop();
  const std::string out = fileContents(child.out);
  EXPECT_EQ(code, 130) << out << fileContents(child.err);
  EXPECT_NE(out.find("replayed "), std::string::npos) << out;
  EXPECT_GE(received.size(), 3u * 64u) << "several passes of 64 datagrams in 0.8 s";
  const auto expected = readCapture(file, 7502);
  ASSERT_EQ(expected.size(), 64u);
  for (std::size_t i = 0; i < received.size(); ++i)
    ASSERT_EQ(received[i].payload, expected[i % 64].payload) << "datagram " << i << ": passes repeat in order";
}

TEST(ReplayCommand, RefusesRemoteTargetsAndBadRates) {
  RIGCAL_REQUIRE_DATA(file, "velodyne/vlp16_dual.pcap");
  test::TempDir dir;
  Child child = spawnRigcal(dir, {"replay", file.string(), "--to", "192.0.2.1"});
  EXPECT_EQ(waitExit(child), 2);
  std::string err = fileContents(child.err);
  EXPECT_NE(err.find("192.0.2.1 is outside 127.0.0.0/8"), std::string::npos) << err;
  EXPECT_NE(err.find("--allow-remote"), std::string::npos) << err;

  child = spawnRigcal(dir, {"replay", file.string(), "--to", "127.0.0.1", "--rate", "fast"});
  EXPECT_EQ(waitExit(child), 2);
  err = fileContents(child.err);
  EXPECT_NE(err.find("--rate: 'fast'"), std::string::npos) << err;

  child = spawnRigcal(dir, {"replay", (dir / "missing.pcap").string(), "--to", "127.0.0.1"});
  EXPECT_EQ(waitExit(child), 4);
  err = fileContents(child.err);
  EXPECT_NE(err.find("missing.pcap"), std::string::npos) << err;
}

}  // namespace
}  // namespace rigcal::drivers
