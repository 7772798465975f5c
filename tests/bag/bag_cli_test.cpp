// The real rigcal binary on real bags: `decode --bag` writes the same scan files as decoding the pcap,
// `inspect` lists topics, types, counts, rates and frame ids; bag errors are one line with exit code 4.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>

#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

std::string fileBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(BagCli, DecodeBagWritesTheSameScanFilesAsThePcap) {
  RIGCAL_REQUIRE_DATA(bag, "bags/nebula_xt32");
  RIGCAL_REQUIRE_DATA(pcap, "hesai/xt32_dual.pcap");
  RIGCAL_REQUIRE_DATA(csv, "hesai/PandarXT32.csv");
  TempDir out;
  const auto b = runRigcal({"decode", "--bag", bag.string(), "--sensor", "PandarXT32", "--calibration", csv.string(),
                            "--out", (out / "bag").string()});
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_NE(b.out.find("bag topic /pandar_packets (pandar_msgs/msg/PandarScan)"), std::string::npos) << b.out;
  const auto p = runRigcal({"decode", pcap.string(), "--sensor", "PandarXT32", "--calibration", csv.string(), "--out",
                            (out / "pcap").string()});
  ASSERT_EQ(p.exit_code, 0) << p.err;
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(out / "pcap")) {
    const auto twin = out / "bag" / entry.path().filename();
    ASSERT_TRUE(std::filesystem::exists(twin)) << twin;
    EXPECT_EQ(fileBytes(entry.path()), fileBytes(twin)) << entry.path().filename();
    ++files;
  }
  EXPECT_EQ(files, 5u);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(out / "bag"), std::filesystem::directory_iterator{}),
            std::ptrdiff_t(files));
}

TEST(BagCli, DecodeBagErrorsAreOneLineWithExitCode4) {
  RIGCAL_REQUIRE_DATA(bag, "bags/nebula_vlp32");
  TempDir out;
  const auto r = runRigcal({"decode", "--bag", bag.string(), "--topic", "/points", "--sensor", "VLP-32C", "--out",
                            out.path().string()});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(r.err.find("topic /points not in the bag; it has /sensing/lidar/front/velodyne_packets"),
            std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  std::filesystem::create_directories(out / "empty");
  const auto e = runRigcal({"decode", "--bag", (out / "empty").string(), "--sensor", "VLP-32C", "--out",
                            out.path().string()});
  EXPECT_EQ(e.exit_code, 4);
  EXPECT_NE(e.err.find("empty: empty bag"), std::string::npos) << e.err;
  const auto both = runRigcal({"decode", "--sensor", "VLP-32C", "--out", out.path().string()});
  EXPECT_EQ(both.exit_code, 2) << both.err;
}

TEST(BagCli, InspectListsTopicsTypesCountsRatesAndFrameIds) {
  RIGCAL_REQUIRE_DATA(vlp32, "bags/nebula_vlp32");
  RIGCAL_REQUIRE_DATA(talker, "bags/rosbag2/sqlite3_talker");
  const auto v = runRigcal({"inspect", vlp32.string()});
  ASSERT_EQ(v.exit_code, 0) << v.err;
  const auto row = v.out.substr(v.out.find("/sensing/lidar/front/velodyne_packets"));
  std::istringstream fields(row);
  std::string topic, type, frame;
  std::uint64_t count = 0;
  double rate = 0, mb = 0;
  fields >> topic >> type >> count >> rate >> mb >> frame;
  EXPECT_EQ(type, "velodyne_msgs/msg/VelodyneScan");
  EXPECT_EQ(count, 5u);
  EXPECT_NEAR(rate, 10.0, 1.0) << "a 600 rpm VLP-32C: one scan message per turn (log times jitter)";
  EXPECT_FALSE(frame.empty());
  EXPECT_NE(frame, "-") << "the frame id comes from the messages' header";
  const auto t = runRigcal({"inspect", talker.string()});
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_NE(t.out.find("20 messages"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("std_msgs/msg/String"), std::string::npos) << t.out;
}

}  // namespace
}  // namespace rigcal::test
