// Issue 18 (UDP): the README's replay-to-localhost path with the simulator's own rig delivers packets
// (its sensors receive on a loopback bind), and datagrams the source-address filter drops are counted and
// reported with their source instead of vanishing.
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

class TrustUdp : public ::testing::Test {
 protected:
  void SetUp() override {
    prefix_ = "rigcal-test-" + std::to_string(::getpid()) + "-" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".";
    port_ = 30000 + int(::getpid() % 20000);
    const auto sim = runRigcal({"sim", "--scenario", "parking-lot", "--duration", "0.5", "--out", dir_.path().string()});
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
    std::ifstream in(dir_ / "rig.yaml");
    rig_text_ = {std::istreambuf_iterator<char>(in), {}};
    ASSERT_NE(rig_text_.find("port: 2368, address: 192.168.1.201, bind: 127.0.0.1"), std::string::npos) << rig_text_;
    // front_left moves to a port of this test's own (tests run in parallel).
    rig_text_ = std::regex_replace(rig_text_, std::regex("port: 2368,"), "port: " + std::to_string(port_) + ",");
  }
  void TearDown() override { fs::remove("/dev/shm/" + prefix_ + "front_left"); }

  // Runs the live driver of front_left on `rig`, replays the capture's front_left packets to 127.0.0.1,
  // and returns what the driver printed.
  CommandResult driveFromReplay(const std::string& rig) {
    std::ofstream(dir_ / "live.yaml", std::ios::trunc) << rig;
    RigcalProcess driver({"driver", "--config", (dir_ / "live.yaml").string(), "--sensor", "front_left", "--live",
                          "--shm-prefix", prefix_});
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!fs::exists("/dev/shm/" + prefix_ + "front_left") && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the ring exists once the socket is bound
    const auto replay = runRigcal({"replay", (dir_ / "recording.pcap").string(), "--to", "127.0.0.1", "--rate", "max",
                                   "--port", "2368", "--port-offset", std::to_string(port_ - 2368)});
    EXPECT_EQ(replay.exit_code, 0) << replay.err;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the last datagrams are read
    driver.kill(SIGINT);
    return driver.wait();
  }

  TempDir dir_;
  std::string prefix_, rig_text_;
  int port_ = 0;
};

TEST_F(TrustUdp, ReplayToLocalhostReachesTheSimulatorsRig) {
  const CommandResult r = driveFromReplay(rig_text_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex("(\\d+) scans published, .*; (\\d+) packets"))) << r.out;
  EXPECT_GT(std::stoul(m[1]), 0u) << r.out;
  EXPECT_GT(std::stoul(m[2]), 300u) << r.out;
  EXPECT_EQ(r.err.find("dropped by the source-address filter"), std::string::npos) << r.err;
}

TEST_F(TrustUdp, DatagramsTheAddressFilterDropsAreReportedWithTheirSource) {
  const CommandResult r = driveFromReplay(std::regex_replace(rig_text_, std::regex(", bind: 127.0.0.1"), ""));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("; 0 packets"), std::string::npos) << r.out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex("warning: (\\d+) datagrams on port " + std::to_string(port_) +
                                                     " dropped by the source-address filter \\(sensor address "
                                                     "192.168.1.201\\), the last from 127.0.0.1:")))
      << r.err;
  EXPECT_GT(std::stoul(m[1]), 300u);
}

}  // namespace
}  // namespace rigcal::test
