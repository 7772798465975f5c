// A simulated RS-Helios-16P through the real binaries, as a user runs it: `rigcal sim` writes the
// capture and a rig.yaml with the DIFOP info_port; `rigcal replay --clock now --config rig.yaml` restamps
// and sends both ports to 127.0.0.1 in real time, and `rigcal driver --live` on that rig makes scans of them.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <thread>

#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;

TEST(RobosenseSimCli, ReplayWithClockNowReachesTheLiveDriverOnBothPorts) {
  TempDir dir;
  std::ofstream(dir / "helios.yaml") << "scenario: helios-live\nseed: 5\nrig:\n  mapping_lidar: top\n  sensors:\n"
                                        "    - {name: top, model: RS-Helios-16P, address: 192.168.1.200, port: 6699, "
                                        "extrinsic: {z: 1.9}}\nscene: {layout: parking-lot}\ntrajectory:\n"
                                        "  start: {x: -20, y: -6, speed_kmh: 6}\n  segments: [{type: cruise, duration: 0.6}]\n";
  const auto sim = runRigcal({"sim", "--scenario", (dir / "helios.yaml").string(), "--out", dir.path().string()});
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  std::ifstream in(dir / "rig.yaml");
  std::string rig{std::istreambuf_iterator<char>(in), {}};
  ASSERT_NE(rig.find("source: {port: 6699, info_port: 7788, address: 192.168.1.200, bind: 127.0.0.1}"), std::string::npos)
      << rig;
  ASSERT_EQ(rig.find("calibration:"), std::string::npos) << "the angles come in the DIFOP";

  // Ports of this test's own (tests run in parallel); replay moves every destination port by the offset.
  const int offset = 20000 + int(::getpid() % 20000);
  rig = std::regex_replace(rig, std::regex("port: 6699, info_port: 7788"),
                           "port: " + std::to_string(6699 + offset) + ", info_port: " + std::to_string(7788 + offset));
  std::ofstream(dir / "live.yaml") << rig;
  const std::string prefix = "rigcal-test-" + std::to_string(::getpid()) + "-helios.";
  RigcalProcess driver({"driver", "--config", (dir / "live.yaml").string(), "--sensor", "top", "--live",
                        "--shm-prefix", prefix});
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!fs::exists("/dev/shm/" + prefix + "top") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the ring exists once the sockets are bound
  const auto replay = runRigcal({"replay", (dir / "recording.pcap").string(), "--to", "127.0.0.1", "--rate", "1",
                                 "--clock", "now", "--config", (dir / "rig.yaml").string(), "--port-offset",
                                 std::to_string(offset)});
  EXPECT_EQ(replay.exit_code, 0) << replay.err;
  const std::string said = replay.out + replay.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(said, m, std::regex("restamped top (\\d+) packets"))) << said;
  const unsigned long msop = std::stoul(m[1]);
  EXPECT_GT(msop, 600u);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the last datagrams are read
  driver.kill(SIGINT);
  const CommandResult r = driver.wait();
  fs::remove("/dev/shm/" + prefix + "top");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex("(\\d+) scans published, .*; (\\d+) packets, (\\d+) malformed")))
      << r.out;
  // Scans at all: the DIFOP came through its port (data waits for it). Real time keeps loopback losses
  // away, but a loaded test machine may still drop a few datagrams.
  EXPECT_GE(std::stoul(m[1]), 4u) << r.out;
  EXPECT_GE(std::stoul(m[2]), msop * 9 / 10) << r.out;
  EXPECT_LE(std::stoul(m[2]), msop + 1) << "the data packets and one DIFOP: " << r.out;
  EXPECT_EQ(std::stoul(m[3]), 0u);
}

}  // namespace
}  // namespace rigcal::test
