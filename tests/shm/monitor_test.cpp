// `rigcal monitor --once`: the table shows live rings, configured-but-absent rings and broken segments.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "rigcal/shm/ring_segment.hpp"
#include "ring_test_support.hpp"
#include "subprocess.hpp"
#include "test_data.hpp"

namespace rigcal::shm {
namespace {

using namespace std::chrono_literals;
using test::Subprocess;

/// Runs `rigcal monitor --once --interval 0.3 <extra>` with the test's prefix; returns stdout.
std::string monitorOnce(const test::UniquePrefix& prefix, std::vector<std::string> extra = {}) {
  std::vector<std::string> argv = {rigcal::test::rigcalBinary().string(), "monitor", "--once", "--interval", "0.3"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  Subprocess monitor(argv, {"RIGCAL_SHM_PREFIX=" + prefix.str()});
  EXPECT_EQ(monitor.wait(10s), 0) << monitor.errText();
  std::string out;
  for (const auto& l : monitor.lines()) out += l + "\n";
  return out;
}

/// The table row of `ring`, or "".
std::string rowOf(const std::string& table, const std::string& ring) {
  std::istringstream in(table);
  for (std::string line; std::getline(in, line);) {
    if (line.compare(0, ring.size() + 1, ring + " ") == 0) return line;
  }
  return {};
}

TEST(Monitor, ShowsALiveRingWithItsRates) {
  test::UniquePrefix prefix;
  Subprocess writer({test::peerPath(), "writer", "--prefix", prefix.str(), "--sensor", "top", "--points", "1000",
                     "--count", "1000", "--rate", "50"});
  ASSERT_TRUE(writer.waitForLine("ready", 5s)) << writer.errText();
  Subprocess reader({test::peerPath(), "reader", "--prefix", prefix.str(), "--sensor", "top", "--points", "1000",
                     "--timeout-ms", "5000"});
  ASSERT_TRUE(reader.waitForLine("started", 5s));
  const std::string table = monitorOnce(prefix);
  EXPECT_NE(table.find("SCANS/S"), std::string::npos) << table;
  const std::string row = rowOf(table, prefix.str() + "top");
  ASSERT_FALSE(row.empty()) << table;
  std::istringstream cols(row);
  std::string ring, status, pid, epoch, scans_s;
  cols >> ring >> status >> pid >> epoch >> scans_s;
  EXPECT_EQ(status, "alive") << row;
  EXPECT_EQ(pid, std::to_string(writer.pid())) << row;
  EXPECT_EQ(epoch, "1") << row;
  EXPECT_GT(std::stod(scans_s), 20.0) << row;  // 50 Hz, measured over 0.3 s
  EXPECT_LT(std::stod(scans_s), 80.0) << row;
}

TEST(Monitor, ListsConfiguredSensorsEvenWithoutRingsAndReportsBrokenSegments) {
  test::UniquePrefix prefix;
  {
    std::ofstream out(segmentPath(prefix.str() + "front_left"), std::ios::binary);
    out << std::string(8192, '\x11');
  }
  const std::string table =
      monitorOnce(prefix, {"--config", std::string(RIGCAL_RIGS_DIR) + "/velodyne-car.yaml"});
  EXPECT_NE(rowOf(table, prefix.str() + "top").find(" absent "), std::string::npos) << table;
  EXPECT_NE(rowOf(table, prefix.str() + "front_right").find(" absent "), std::string::npos) << table;
  EXPECT_NE(rowOf(table, prefix.str() + "front_left").find(" error "), std::string::npos) << table;
  EXPECT_NE(table.find("is not a rigcal scan ring"), std::string::npos) << table;
}

TEST(Monitor, SaysSoWhenThereAreNoRings) {
  test::UniquePrefix prefix;
  EXPECT_NE(monitorOnce(prefix).find("(no rings under"), std::string::npos);
}

}  // namespace
}  // namespace rigcal::shm
