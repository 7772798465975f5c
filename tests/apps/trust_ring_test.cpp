// Issue 18 (shared memory): `rigcal driver` never adopts a ring another user can touch, creates its own
// private to its user, and bounds --slots by the bytes the ring takes; `rigcal map --shm` follows a driver
// that is killed and restarted; a driver process's malformed packets reach the progress line of
// `map --shm` and the summary and report.json of `calibrate --shm`.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigcal/shm/ring_inspect.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;

/// A copy of `pcap` (Ethernet, classic pcap) in which `count` Velodyne data packets from three quarters of
/// the way in have their first block header zeroed: the decoder drops each one as malformed.
fs::path withMalformedPackets(const fs::path& pcap, const fs::path& out, int count) {
  std::ifstream in(pcap, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  constexpr std::size_t kRecordHeader = 16, kEthIpUdp = 42, kDataPayload = 1206;
  std::vector<std::size_t> payloads;
  for (std::size_t at = 24; at + kRecordHeader <= bytes.size();) {
    std::uint32_t captured = 0;
    std::memcpy(&captured, bytes.data() + at + 8, 4);
    if (captured == kEthIpUdp + kDataPayload) payloads.push_back(at + kRecordHeader + kEthIpUdp);
    at += kRecordHeader + captured;
  }
  // Three quarters into the capture: a reader counts what its ring carried from the first scan it read on,
  // and a reader attaches up to a poll (100 ms) after the ring appears, later on a busy machine.
  for (int i = 0; i < count; ++i) {
    const std::size_t at = payloads.at(payloads.size() * 3 / 4 + std::size_t(i) * 3);
    bytes[at] = bytes[at + 1] = 0;  // block 0's 0xFFEE
  }
  std::ofstream(out, std::ios::binary) << bytes;
  return out;
}

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

/// `command` run as user nobody (setpriv), through the shell; its exit code.
int asNobody(const std::string& command) {
  const std::string line = "setpriv --reuid=65534 --regid=65534 --clear-groups sh -c '" + command + "' 2>/dev/null";
  const int status = std::system(line.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

// The hijack as it happens: a second, unprivileged user creates the ring's name world-writable before the
// driver starts (no root chown, as in ARingAnotherUserCreatedIsRefused). The driver refuses it with a
// one-line message naming the owner and the way out, and neither sizes nor writes it.
TEST_F(TrustRing, ARingASecondUserPreCreatedIsRefused) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to run a second user (setpriv)";
  if (std::system("setpriv --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "setpriv is needed";
  ASSERT_EQ(asNobody("umask 0; : > " + segment().string() + " && chmod 0666 " + segment().string()), 0);
  struct stat st {};
  ASSERT_EQ(::stat(segment().c_str(), &st), 0);
  ASSERT_EQ(st.st_uid, 65534u) << "the second user owns it";
  ASSERT_EQ(st.st_mode & 07777, 0666u);
  const CommandResult r = RigcalProcess(driverArgs(pcap)).wait();
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("belongs to uid 65534"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  ASSERT_EQ(::stat(segment().c_str(), &st), 0);
  EXPECT_EQ(st.st_size, 0) << "not sized or written";
  EXPECT_EQ(st.st_uid, 65534u) << "left alone";
}

// A ring the driver created (0600) is closed to a second user: nobody cannot read, write or truncate it
// while root's driver runs. (Root itself can read it: the check is that the mode really protects it.)
TEST_F(TrustRing, ASecondUserCannotReadOurRing) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to run a second user (setpriv)";
  if (std::system("setpriv --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "setpriv is needed";
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
  EXPECT_EQ(std::system(("head -c 64 " + segment().string() + " >/dev/null").c_str()), 0) << "root reads it";
  EXPECT_NE(asNobody("head -c 64 " + segment().string() + " >/dev/null"), 0) << "nobody read the ring";
  EXPECT_NE(asNobody("printf x >> " + segment().string()), 0) << "nobody wrote the ring";
  EXPECT_NE(asNobody("truncate -s 0 " + segment().string()), 0) << "nobody truncated the ring";
  ASSERT_EQ(reader.read(scan, std::chrono::seconds(30)), shm::ReadStatus::kScan) << "the ring still works";
  driver.kill(SIGINT);
  driver.wait();
}

// A Velodyne stream on the port of a sensor the rig says is a Hesai: the driver holds those packets back
// from its decoder, counts them and says once what they are and where they came from.
TEST_F(TrustRing, PacketsOfAnotherModelAreCountedAndNamed) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  std::ofstream(rig_) << "sensors:\n  - name: roof\n    model: PandarXT32\n    source: {port: 2368}\n"
                         "roles:\n  mapping_lidar: roof\n";
  const CommandResult r = runRigcal(driverArgs(pcap));
  EXPECT_LT(r.exit_code, 128) << r.err;
  const std::string line = "warning: sensor 'roof': ";
  const auto at = r.err.find(line);
  ASSERT_NE(at, std::string::npos) << r.err;
  const std::string warning = r.err.substr(at, r.err.find('\n', at) - at);
  EXPECT_NE(warning.find(" packets of another model (Velodyne, 1206 B) on its port 2368 (it is a PandarXT32), the "
                         "last from "),
            std::string::npos)
      << warning;
  EXPECT_EQ(r.err.find(line, at + 1), std::string::npos) << "one line: " << r.err;
  EXPECT_NE(r.out.find(": 0 scans published, 0 too large for a slot; 0 packets, 0 malformed"), std::string::npos) << "none reached the decoder: " << r.out;
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

// A driver process that drops malformed packets: `map --shm` shows them for its sensor as an in-process
// driver's are shown (the count crosses the ring with each scan), and the driver's exit summary agrees.
TEST_F(TrustRing, MapShowsTheMalformedPacketsOfADriverProcess) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  const fs::path damaged = withMalformedPackets(pcap, dir_ / "damaged.pcap", 5);
  std::vector<std::string> args = driverArgs(damaged, "64");
  args[8] = "1";  // --rate: the reader attaches (it polls every 100 ms) long before the last scan
  RigcalProcess map({"map", "--config", rig_.string(), "--shm", "--shm-prefix", prefix_});
  const CommandResult driver = RigcalProcess(args).wait();
  const CommandResult m = map.wait();
  ASSERT_EQ(driver.exit_code, 0) << driver.err;
  EXPECT_NE(driver.out.find(" packets, 5 malformed, "), std::string::npos) << driver.out;
  EXPECT_LT(m.exit_code, 128) << m.err;
  EXPECT_TRUE(std::regex_search(m.out, std::regex(R"(scans [1-9]\d* \|.*\| roof (lost \d+ pkts, )?5 malformed)")))
      << m.out << m.err;
}

// `calibrate --shm` with a calibration lidar whose driver process dropped malformed packets: the summary
// warns with the count and report.json's input carries it per sensor, as for a damaged pcap.
TEST_F(TrustRing, CalibrateReportsTheMalformedPacketsOfADriverProcess) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  const fs::path damaged = withMalformedPackets(pcap, dir_ / "damaged.pcap", 4);
  // Each driver reads its own capture on port 2368; calibrate only needs the sensors' names.
  const fs::path left_rig = dir_ / "left.yaml", rig = dir_ / "calibrate.yaml", out = dir_ / "out";
  std::ofstream(left_rig) << "sensors:\n  - name: left\n    model: HDL-32E\n    source: {port: 2368}\n"
                             "roles:\n  mapping_lidar: left\n";
  std::ofstream(rig) << "sensors:\n  - name: roof\n    model: HDL-32E\n    source: {port: 2368}\n"
                        "  - name: left\n    model: HDL-32E\n    source: {port: 2369}\n"
                        "roles:\n  mapping_lidar: roof\n  calibration_lidars: [left]\n";
  RigcalProcess calibrate({"calibrate", "--config", rig.string(), "--shm", "--shm-prefix", prefix_, "--out",
                           out.string()});
  std::vector<std::string> roof = driverArgs(pcap, "64"), left = driverArgs(damaged, "64");
  roof[8] = "1";
  // Half speed: the damaged packets come ~0.5 s after the left ring appears, long after calibrate's reader
  // attached (once, at load, it attached after them and counted 1 of 4).
  left[8] = "0.5";
  left[2] = left_rig.string();
  left[4] = "left";
  RigcalProcess roof_driver(roof), left_driver(left);
  EXPECT_EQ(roof_driver.wait().exit_code, 0);
  EXPECT_EQ(left_driver.wait().exit_code, 0);
  const CommandResult c = calibrate.wait();
  fs::remove("/dev/shm/" + prefix_ + "left");
  EXPECT_LT(c.exit_code, 128) << c.err;
  // The zeroed packets also leave gaps in the sweep, which the driver counts as lost (as in process).
  EXPECT_TRUE(std::regex_search(c.err, std::regex(R"(warning: left: \d+ of [1-9]\d* packets lost, 4 malformed, 0 too late)")))
      << c.err;
  EXPECT_EQ(c.err.find("warning: roof: "), std::string::npos) << "its input is clean\n" << c.err;
  std::ifstream report(out / "report.json");
  ASSERT_TRUE(report.good()) << c.out << c.err;
  const auto j = nlohmann::json::parse(report);
  EXPECT_EQ(j["input"]["left_packets_malformed"], "4") << j["input"].dump();
  EXPECT_EQ(j["input"]["roof_packets_malformed"], "0") << j["input"].dump();
  EXPECT_NE(j["input"]["left_packets_lost"], nullptr) << j["input"].dump();
  EXPECT_NE(j["warnings"].dump().find("4 malformed"), std::string::npos) << j["warnings"].dump();
}

}  // namespace
}  // namespace rigcal::test
