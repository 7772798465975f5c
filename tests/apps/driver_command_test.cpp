// `rigcal driver` as a real process writing a real shared-memory ring, read here as the pipeline would.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "rigcal/config/rig_config.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

// Generous: a sanitizer-instrumented driver on a loaded 2-core machine starts and decodes slowly.
constexpr std::chrono::seconds kScanWait{30};

class DriverCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    prefix_ = "rigcal-test-" + std::to_string(::getpid()) + "-" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".";
    rig_ = dir_ / "rig.yaml";
    std::ofstream(rig_) << "sensors:\n  - name: roof\n    model: HDL-32E\n    source: {port: 2368}\n"
                           "roles:\n  mapping_lidar: roof\n";
  }
  std::vector<std::string> driverArgs(const std::filesystem::path& pcap, const std::string& rate) {
    return {"driver", "--config", rig_.string(), "--sensor", "roof", "--pcap", pcap.string(), "--rate", rate,
            "--shm-prefix", prefix_, "--slots", "64"};
  }
  shm::ScanRingReader reader() {
    shm::ReaderOptions r;
    r.sensor = "roof";
    r.name_prefix = prefix_;
    r.start_at = shm::ReaderOptions::StartAt::kOldest;
    r.liveness_period = std::chrono::milliseconds(20);
    return shm::ScanRingReader(r);
  }
  // What the same driver code gives in-process, as fast as possible.
  std::vector<Scan> offline(const std::filesystem::path& pcap) {
    const config::RigConfig rig = config::loadRigConfig(rig_);
    std::vector<Scan> scans;
    std::atomic<bool> stop{false};
    pipeline::SensorDriver d(rig.sensor("roof"), {pcap, 0.0}, stop, [&](Scan&& s) { scans.push_back(std::move(s)); });
    d.run();
    return scans;
  }
  TempDir dir_;
  std::filesystem::path rig_;
  std::string prefix_;
};

TEST_F(DriverCommand, PublishesEveryScanIntactIntoItsRing) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  const std::vector<Scan> expected = offline(pcap);
  ASSERT_GE(expected.size(), 5u);
  auto r = reader();  // attaches as soon as the driver creates the ring
  RigcalProcess driver(driverArgs(pcap, "4"));
  std::vector<Scan> got;
  Scan scan;
  while (true) {
    const auto status = r.read(scan, kScanWait);
    if (status == shm::ReadStatus::kScan) got.push_back(scan);
    if (status != shm::ReadStatus::kScan) break;
  }
  const CommandResult result = driver.wait();
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find(std::to_string(expected.size()) + " scans published"), std::string::npos) << result.out;
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].stamp_ns, expected[i].stamp_ns) << i;
    EXPECT_EQ(got[i].x, expected[i].x) << i;
    EXPECT_EQ(got[i].offset_ns, expected[i].offset_ns) << i;
  }
  EXPECT_FALSE(std::filesystem::exists("/dev/shm/" + prefix_ + "roof")) << "clean shutdown unlinks the ring";
}

TEST_F(DriverCommand, KilledDriverIsReportedDeadAndARestartTakesOverItsRing) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  auto r = reader();
  Scan scan;
  {
    RigcalProcess first(driverArgs(pcap, "0.5"));  // ~1 s of capture at half speed
    ASSERT_EQ(r.read(scan, kScanWait), shm::ReadStatus::kScan);
    first.kill(SIGKILL);
    EXPECT_EQ(first.wait().exit_code, 128 + SIGKILL);
  }
  // Drain what the dead writer left, then the reader reports it gone.
  shm::ReadStatus status;
  while ((status = r.read(scan, kScanWait)) == shm::ReadStatus::kScan) {
  }
  EXPECT_EQ(status, shm::ReadStatus::kWriterGone);
  const std::uint64_t first_epoch = r.epoch();

  RigcalProcess second(driverArgs(pcap, "max"));
  std::size_t scans_after_restart = 0;
  while (r.read(scan, kScanWait) == shm::ReadStatus::kScan) ++scans_after_restart;
  const CommandResult result = second.wait();
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("took over a stale ring"), std::string::npos) << result.out;
  EXPECT_GT(r.epoch(), first_epoch);
  EXPECT_EQ(scans_after_restart, offline(pcap).size());
}

// --low-latency needs the right to open /dev/cpu_dma_latency (root). Without it the driver says so in one
// line and runs as it would without the option; with it, no warning. Run once as root (when the test is)
// and once as an unprivileged user (setpriv to nobody), so both paths are exercised on any machine.
TEST_F(DriverCommand, LowLatencyWithoutTheRightWarnsOnceAndStillPublishes) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  namespace fs = std::filesystem;
  fs::permissions(dir_.path(), fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                                   fs::perms::others_read | fs::perms::others_exec);
  std::vector<std::string> args = driverArgs(pcap, "max");
  args.push_back("--low-latency");
  const std::string warning = "warning: --low-latency not in effect: /dev/cpu_dma_latency: ";

  std::vector<std::string> unprivileged;
  if (::geteuid() == 0) {
    if (std::system("setpriv --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "setpriv is needed to drop root";
    unprivileged = {"setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"};
    const CommandResult root = RigcalProcess(args).wait();
    ASSERT_EQ(root.exit_code, 0) << root.err;
    EXPECT_EQ(root.err.find("--low-latency"), std::string::npos) << "root holds the limit: " << root.err;
  }
  const CommandResult user = RigcalProcess(args, unprivileged).wait();
  ASSERT_EQ(user.exit_code, 0) << user.err;
  const std::size_t at = user.err.find(warning);
  ASSERT_NE(at, std::string::npos) << user.err;
  EXPECT_EQ(user.err.find(warning, at + 1), std::string::npos) << "warned once";
  EXPECT_NE(user.err.find("Permission denied", at), std::string::npos) << user.err;
  EXPECT_NE(user.out.find(std::to_string(offline(pcap).size()) + " scans published"), std::string::npos) << user.out;
}

// Every model added in round 2 runs as its own driver process: each sweep of its real capture reaches the
// ring intact (the slot is sized for the model's largest scan), as the in-process driver decodes it.
TEST_F(DriverCommand, EachNewModelPublishesItsCaptureIntoItsRing) {
  struct Case {
    const char* model;
    const char* capture;
    const char* source;       // the capture's ports
    const char* calibration;  // "" where the sensor sends its own angles (the Helios' DIFOP)
  };
  for (const Case& c : {Case{"Pandar40P", "hesai/pandar40p_dual.pcap", "{port: 2368}", "hesai/Pandar40P.csv"},
                        Case{"Pandar64", "hesai/pandar64_dual.pcap", "{port: 2368}", "hesai/Pandar64.csv"},
                        Case{"PandarQT64", "hesai/pandarqt64_dual.pcap", "{port: 2368}", "hesai/PandarQT64.csv"},
                        Case{"PandarXT32M", "hesai/xt32m_laststrongest.pcap", "{port: 2368}", "hesai/PandarXT32M.csv"},
                        Case{"RS-Helios-16P", "robosense/helios16p.pcap", "{port: 6699, info_port: 7788}", ""}}) {
    SCOPED_TRACE(c.model);
    RIGCAL_REQUIRE_DATA(pcap, c.capture);
    std::ofstream rig(rig_);
    rig << "sensors:\n  - name: roof\n    model: " << c.model << "\n    source: " << c.source << "\n";
    if (*c.calibration != '\0') rig << "    calibration: " << (dataDir() / c.calibration).string() << "\n";
    rig << "roles:\n  mapping_lidar: roof\n";
    rig.close();
    const std::vector<Scan> expected = offline(pcap);
    ASSERT_GE(expected.size(), 3u);
    auto r = reader();
    // At the recorded rate the driver lives for the capture's half second, so the reader (polling for the
    // ring) is attached before the clean exit unlinks it; at "max" the ring could come and go unseen.
    RigcalProcess driver(driverArgs(pcap, "1"));
    std::vector<Scan> got;
    Scan scan;
    while (r.read(scan, kScanWait) == shm::ReadStatus::kScan) got.push_back(scan);
    const CommandResult result = driver.wait();
    ASSERT_EQ(result.exit_code, 0) << result.out << result.err;
    EXPECT_NE(result.out.find(" 0 too large for a slot"), std::string::npos) << result.out;
    ASSERT_EQ(got.size(), expected.size()) << result.out;
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].stamp_ns, expected[i].stamp_ns) << i;
      EXPECT_EQ(got[i].x, expected[i].x) << i;
      EXPECT_EQ(got[i].ring, expected[i].ring) << i;
    }
  }
}

TEST_F(DriverCommand, BadSensorAndMissingInputAreClearErrors) {
  const auto unknown = runRigcal({"driver", "--config", rig_.string(), "--sensor", "rooff", "--live"});
  EXPECT_EQ(unknown.exit_code, 3);
  EXPECT_NE(unknown.err.find("no sensor named 'rooff'"), std::string::npos) << unknown.err;
  EXPECT_EQ(runRigcal({"driver", "--config", rig_.string(), "--sensor", "roof"}).exit_code, 2);
  EXPECT_EQ(runRigcal({"driver", "--config", rig_.string(), "--sensor", "roof", "--live", "--pcap",
                       rig_.string()}).exit_code, 2);
}

}  // namespace
}  // namespace rigcal::test
