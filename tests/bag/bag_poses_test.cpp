// calibrate-pose from a bag's poses (nav_msgs/Odometry, or /tf between two frames) as from the CSV.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <sstream>

#include "bag_pipeline_support.hpp"
#include "run_command.hpp"
#include "sanitizers.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;
using bag::test::SqliteBagWriter;

/// poses.csv rows (timestamp_ns, index, px py pz, qw qx qy qz) as nav_msgs/Odometry and as /tf map ->
/// base_link, the values copied exactly (the bag holds what the CSV holds).
void writePoseTopics(SqliteBagWriter& bag, const fs::path& csv) {
  const int odom = bag.topic("/odom", "nav_msgs/msg/Odometry");
  const int tf = bag.topic("/tf", "tf2_msgs/msg/TFMessage");
  std::istringstream in(fileContents(csv));
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream row(line);
    std::vector<std::string> f;
    for (std::string v; std::getline(row, v, ',');) f.push_back(v);
    ASSERT_EQ(f.size(), 9u) << line;
    const TimeNs stamp = std::stoll(f[0]);
    const double p[3] = {std::stod(f[2]), std::stod(f[3]), std::stod(f[4])};
    const double q[4] = {std::stod(f[6]), std::stod(f[7]), std::stod(f[8]), std::stod(f[5])};  // x y z w
    bag::test::CdrWriter o;
    o.putHeader(stamp, "map").putString("base_link");
    for (double v : p) o.put(v);
    for (double v : q) o.put(v);
    for (int i = 0; i < 36 + 6 + 36; ++i) o.put(0.0);
    bag.write(odom, stamp, o.bytes());
    bag::test::CdrWriter t;
    t.put(std::uint32_t(1)).putHeader(stamp, "map").putString("base_link");
    for (double v : p) t.put(v);
    for (double v : q) t.put(v);
    bag.write(tf, stamp, t.bytes());
  }
}

YAML::Node poseResult(const fs::path& out) { return YAML::LoadFile((out / "calibration.yaml").string())["pose_sensor"]["lidar"]; }

// calibrate-pose with the lidar's packets and the INS poses from a bag (Odometry, or /tf between two
// frames) gives the result of the pcap + CSV path.
TEST(BagPoses, CalibratePoseFromOdometryAndTfEqualsTheCsvPath) {
  TempDir dir;
  const auto sim = runRigcal({"sim", "--scenario", "pose", "--duration", kSanitized ? "3" : "6", "--out",
                              dir.path().string()});
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const config::RigConfig rig = config::loadRigConfig(dir / "rig.yaml");
  {
    SqliteBagWriter bag(dir / "drive.db3");
    bag::test::writePacketTopic(bag, "/sensing/lidar/top/velodyne_packets", rig.sensors.front(), dir / "recording.pcap");
    ASSERT_NO_FATAL_FAILURE(writePoseTopics(bag, dir / "poses.csv"));
  }
  const std::vector<std::string> common{"--config", (dir / "rig.yaml").string(), "--sensor", "lidar", "--keep-ratio",
                                        kSanitized ? "0.002" : "0.01", "--max-evals", kSanitized ? "20" : "60",
                                        "--threads", "1"};
  const auto run = [&](std::vector<std::string> args, const std::string& out) {
    args.insert(args.begin(), "calibrate-pose");
    args.insert(args.end(), common.begin(), common.end());
    args.insert(args.end(), {"--out", (dir / out).string()});
    return runRigcal(args);
  };
  const auto csv = run({"--pcap", (dir / "recording.pcap").string(), "--poses", (dir / "poses.csv").string()}, "csv");
  ASSERT_EQ(csv.exit_code, 0) << csv.out << csv.err;
  const auto odom = run({"--bag", (dir / "drive.db3").string(), "--pose-topic", "/odom"}, "odom");
  ASSERT_EQ(odom.exit_code, 0) << odom.out << odom.err;
  EXPECT_NE(odom.out.find("drive.db3 /odom (re-centred by"), std::string::npos) << odom.out;
  const auto tf = run({"--bag", (dir / "drive.db3").string(), "--pose-tf", "map:base_link"}, "tf");
  ASSERT_EQ(tf.exit_code, 0) << tf.out << tf.err;
  const YAML::Node expected = poseResult(dir / "csv");
  for (const char* out : {"odom", "tf"}) {
    const YAML::Node got = poseResult(dir / out);
    for (const char* key : {"x", "y", "z", "roll", "pitch", "yaw", "time_offset_s"})
      EXPECT_NEAR(got[key].as<double>(), expected[key].as<double>(), 2e-6) << out << ' ' << key;
  }

  const auto wrong = run({"--bag", (dir / "drive.db3").string(), "--pose-topic", "/sensing/lidar/top/velodyne_packets"},
                         "wrong");
  EXPECT_EQ(wrong.exit_code, 4);
  EXPECT_NE(wrong.err.find("has type nebula_msgs/msg/NebulaPackets, not a pose type"), std::string::npos) << wrong.err;
  const auto no_frames = run({"--bag", (dir / "drive.db3").string(), "--pose-tf", "odom:imu"}, "none");
  EXPECT_EQ(no_frames.exit_code, 4);
  EXPECT_NE(no_frames.err.find("no transform between odom and imu on /tf; its frames are base_link, map"),
            std::string::npos) << no_frames.err;
}

}  // namespace
}  // namespace rigcal::test
