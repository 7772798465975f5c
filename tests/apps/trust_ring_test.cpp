// Issue 18 (shared memory): `rigcal driver` never adopts a ring another user can touch, creates its own
// private to its user, and bounds --slots by the bytes the ring takes; `rigcal map --shm` follows a driver
// that is killed and restarted.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <thread>

#include "rigcal/shm/ring_inspect.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;

class TrustRing : public ::testing::Test {
 protected:
  void SetUp() override {
    prefix_ = "rigcal-test-" + std::to_string(::getpid()) + "-" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".";
    rig_ = dir_ / "rig.yaml";
    std::ofstream(rig_) << "sensors:\n  - name: roof\n    model: HDL-32E\n    source: {port: 2368}\n"
                           "roles:\n  mapping_lidar: roof\n";
  }
  void TearDown() override { fs::remove("/dev/shm/" + prefix_ + "roof"); }
  std::vector<std::string> driverArgs(const fs::path& pcap, const std::string& slots = "8") {
    return {"driver", "--config", rig_.string(), "--sensor", "roof", "--pcap", pcap.string(), "--rate", "max",
            "--shm-prefix", prefix_, "--slots", slots};
  }
  [[nodiscard]] fs::path segment() const { return "/dev/shm/" + prefix_ + "roof"; }
  TempDir dir_;
  fs::path rig_;
  std::string prefix_;
};

// Another user pre-creates the ring world-writable (the hijack): the driver refuses it, names the owner,
// and leaves it alone. A ring of its own user but open to others is refused as well.
TEST_F(TrustRing, ARingAnotherUserCreatedIsRefused) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to create a segment owned by another user";
  { std::ofstream(segment()) << ""; }
  ASSERT_EQ(::chown(segment().c_str(), 65534, 65534), 0);
  ASSERT_EQ(::chmod(segment().c_str(), 0666), 0);
  const CommandResult foreign = RigcalProcess(driverArgs(pcap)).wait();
  EXPECT_EQ(foreign.exit_code, 1) << foreign.out << foreign.err;
  EXPECT_NE(foreign.err.find("belongs to uid 65534"), std::string::npos) << foreign.err;
  EXPECT_EQ(fs::file_size(segment()), 0u) << "not sized or written";

  ASSERT_EQ(::chown(segment().c_str(), 0, 0), 0);  // ours, but anyone may write it
  const CommandResult open_to_all = RigcalProcess(driverArgs(pcap)).wait();
  EXPECT_EQ(open_to_all.exit_code, 1) << open_to_all.err;
  EXPECT_NE(open_to_all.err.find("has mode 0666"), std::string::npos) << open_to_all.err;
}

// A ring the driver creates is its user's alone (mode 0600), seen while the driver runs.
TEST_F(TrustRing, ANewRingIsPrivateToItsUser) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  shm::ReaderOptions r;
  r.sensor = "roof";
  r.name_prefix = prefix_;
  r.start_at = shm::ReaderOptions::StartAt::kOldest;
  shm::ScanRingReader reader(r);  // waits for the ring to appear
  std::vector<std::string> args = driverArgs(pcap);
  args[8] = "0.5";  // --rate: keep it alive for a while
  RigcalProcess driver(args);
  Scan scan;
  ASSERT_EQ(reader.read(scan, std::chrono::seconds(30)), shm::ReadStatus::kScan);
  struct stat st {};
  ASSERT_EQ(::stat(segment().c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  EXPECT_EQ(st.st_uid, ::geteuid());
  driver.kill(SIGINT);
  driver.wait();
}

// --slots is bounded by the bytes the ring takes, and the driver says how much it takes.
TEST_F(TrustRing, SlotsAreBoundedByBytes) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  const auto big = runRigcal(driverArgs(pcap, "1024"));
  EXPECT_EQ(big.exit_code, 2) << big.err;
  EXPECT_NE(big.err.find("--slots 1024: the ring would take"), std::string::npos) << big.err;
  EXPECT_NE(big.err.find("the limit is 512.0 MiB, at most"), std::string::npos) << big.err;
  EXPECT_FALSE(fs::exists(segment())) << "refused before allocating";
  const auto small = runRigcal(driverArgs(pcap, "8"));
  EXPECT_EQ(small.exit_code, 0) << small.err;
  EXPECT_NE(small.out.find("(8 slots, "), std::string::npos) << small.out;
  EXPECT_NE(small.out.find(" MiB)"), std::string::npos) << small.out;
}

// A `rigcal driver` killed and restarted under `rigcal map --shm --wait-for-writers`: map says the writer
// died, follows the restarted driver's new epoch with the gap, and is still running to read it.
TEST_F(TrustRing, MapFollowsARestartedDriver) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  std::vector<std::string> args = driverArgs(pcap);
  args[8] = "0.1";  // --rate: 7 scans over 6.5 s
  const auto ring = [&] { return shm::inspectRing(prefix_ + "roof"); };
  const auto until = [](const std::function<bool()>& done) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!done() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    return done();
  };
  RigcalProcess map({"map", "--config", rig_.string(), "--shm", "--shm-prefix", prefix_, "--wait-for-writers"});
  auto first = std::make_unique<RigcalProcess>(args);
  // map's reader holds a record and has read at least one scan of the first driver.
  ASSERT_TRUE(until([&] {
    const auto r = ring();
    return r.readers > 0 && r.write_index >= 1 && r.max_backlog == 0;
  }));
  first->kill(SIGKILL);
  (void)first->wait();
  ASSERT_TRUE(until([&] { return ring().writer == shm::WriterStatus::kDead; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // map's reader notices (liveness: 100 ms)
  const std::uint64_t before = ring().write_index;

  RigcalProcess second(args);  // takes the dead driver's ring over: a new epoch
  ASSERT_TRUE(until([&] {
    const auto r = ring();
    return r.epoch == 2 && r.write_index > before && r.max_backlog == 0 && r.readers > 0;
  })) << "map's reader did not read the restarted driver's scans";
  map.kill(SIGINT);
  const CommandResult m = map.wait();
  second.kill(SIGINT);
  (void)second.wait();
  EXPECT_LT(m.exit_code, 128) << m.err;
  EXPECT_NE(m.err.find("warning: sensor 'roof': the writer of its ring is dead"), std::string::npos) << m.err;
  EXPECT_NE(m.err.find("warning: sensor 'roof': a new writer (epoch 2) after a gap of"), std::string::npos) << m.err;
}

}  // namespace
}  // namespace rigcal::test
