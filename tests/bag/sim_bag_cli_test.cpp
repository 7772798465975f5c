// `rigcal sim --format both` through the real binary: the packet-form MCAP decodes (`decode --bag`) to
// scan files byte-identical to decoding the sim's pcap, for a sensor of every vendor; the PointCloud2
// form holds every simulated sweep point for point (against --dump-scans), and both bags carry
// /tf_static (the rig.yaml initial extrinsics) and /odom (the samples of poses.csv).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/cdr_reader.hpp"
#include "rigcal/bag/point_cloud2_message.hpp"
#include "rigcal/bag/tf_message.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/point_table.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;

std::string fileBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct SimSensor {
  const char* name;
  const char* model;
  const char* address;
  int port;
  const char* option;  // the vendor file rig.yaml names
  const char* file;
};

constexpr SimSensor kSensors[] = {
    {"vlp", "VLP-16", "192.168.1.201", 2368, "--calibration", "vlp.calibration.yaml"},
    {"os", "OS1-64", "10.5.5.88", 7502, "--metadata", "os.json"},
    {"xt", "PandarXT32", "192.168.1.210", 2370, "--calibration", "xt.angles.csv"},
    {"rs", "RS-Helios-16P", "192.168.1.200", 6699, nullptr, nullptr},
};

class SimBag : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    std::ostringstream scenario;
    scenario << "scenario: bag-forms\nseed: 9\nrig:\n  mapping_lidar: vlp\n  sensors:\n";
    double z = 1.5;
    for (const auto& s : kSensors)
      scenario << "    - {name: " << s.name << ", model: " << s.model << ", address: " << s.address
               << ", port: " << s.port << ", extrinsic: {z: " << (z += 0.2) << "}}\n";
    scenario << "scene: {layout: parking-lot}\ntrajectory:\n  start: {x: -20, y: -6, speed_kmh: 6}\n"
                "  segments: [{type: cruise, duration: 0.5}]\n";
    std::ofstream(*dir_ / "scenario.yaml") << scenario.str();
    sim_ = new CommandResult(runRigcal({"sim", "--scenario", (*dir_ / "scenario.yaml").string(), "--out",
                                        (*dir_ / "sim").string(), "--format", "both", "--dump-scans"}));
  }
  static void TearDownTestSuite() {
    delete sim_;
    delete dir_;
  }
  static inline TempDir* dir_ = nullptr;
  static inline CommandResult* sim_ = nullptr;
};

TEST_F(SimBag, WritesThePcapAndBothBags) {
  ASSERT_EQ(sim_->exit_code, 0) << sim_->err;
  for (const char* f : {"recording.pcap", "recording.mcap", "recording_points.mcap"})
    EXPECT_TRUE(fs::exists(dir_->path() / "sim" / f)) << f << "\n" << sim_->out;
  EXPECT_NE(sim_->out.find("packet messages on /<sensor>/packets"), std::string::npos) << sim_->out;
}

TEST_F(SimBag, PacketFormDecodesToTheSameScansAsThePcap) {
  ASSERT_EQ(sim_->exit_code, 0) << sim_->err;
  const fs::path sim = dir_->path() / "sim";
  for (const auto& s : kSensors) {
    std::vector<std::string> common = {"--sensor", s.model};
    if (s.option) common.insert(common.end(), {s.option, (sim / s.file).string()});
    auto from_pcap = common, from_bag = common;
    from_pcap.insert(from_pcap.begin(), {"decode", (sim / "recording.pcap").string(), "--address", s.address});
    from_pcap.insert(from_pcap.end(), {"--out", (dir_->path() / "pcap" / s.name).string()});
    from_bag.insert(from_bag.begin(), {"decode", "--bag", (sim / "recording.mcap").string(), "--topic",
                                       std::string("/") + s.name + "/packets"});
    from_bag.insert(from_bag.end(), {"--out", (dir_->path() / "bag" / s.name).string()});
    const auto p = runRigcal(from_pcap);
    ASSERT_EQ(p.exit_code, 0) << s.name << ": " << p.err;
    const auto b = runRigcal(from_bag);
    ASSERT_EQ(b.exit_code, 0) << s.name << ": " << b.err;
    std::size_t files = 0;
    for (const auto& entry : fs::directory_iterator(dir_->path() / "pcap" / s.name)) {
      const auto twin = dir_->path() / "bag" / s.name / entry.path().filename();
      ASSERT_TRUE(fs::exists(twin)) << twin;
      EXPECT_EQ(fileBytes(entry.path()), fileBytes(twin)) << s.name << " " << entry.path().filename();
      ++files;
    }
    EXPECT_GE(files, 4u) << s.name;
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_->path() / "bag" / s.name), fs::directory_iterator{}),
              std::ptrdiff_t(files))
        << s.name;
  }
}

TEST_F(SimBag, CloudFormHoldsEverySimulatedSweepWithTfStaticAndOdometry) {
  ASSERT_EQ(sim_->exit_code, 0) << sim_->err;
  const fs::path sim = dir_->path() / "sim";
  std::map<std::string, std::vector<Scan>> clouds;
  std::vector<bag::StampedTransform> tf;
  std::vector<std::pair<TimeNs, Eigen::Vector3d>> odometry;
  bag::Bag points(sim / "recording_points.mcap");
  while (const auto m = points.next()) {
    const auto& topic = points.topics()[m->topic];
    if (topic.name == "/tf_static") {
      tf = bag::decodeTfMessage(m->data, "tf");
    } else if (topic.name == "/odom") {
      bag::CdrReader cdr(m->data, "odom");
      const auto header = cdr.readHeader();
      EXPECT_EQ(header.frame_id, "map");
      EXPECT_EQ(cdr.readString("child_frame_id"), "base_link");
      Eigen::Vector3d p;
      for (int i = 0; i < 3; ++i) p[i] = cdr.read<double>("position");
      odometry.emplace_back(header.stamp_ns, p);
    } else {
      ASSERT_EQ(topic.type, bag::kPointCloud2Type);
      const auto cloud = bag::decodePointCloud2(m->data, topic.name);
      EXPECT_EQ("/" + cloud.frame_id + "/points", topic.name);
      clouds[cloud.frame_id].push_back(cloud.scan);
    }
  }
  // Every dumped sweep (PCD) is one cloud of the bag, point for point, point times included.
  for (const auto& s : kSensors) {
    std::vector<fs::path> pcds;
    for (const auto& e : fs::directory_iterator(sim / "scans" / s.name)) pcds.push_back(e.path());
    std::sort(pcds.begin(), pcds.end());
    auto& got = clouds[s.name];
    std::erase_if(got, [](const Scan& c) { return c.empty(); });
    ASSERT_EQ(got.size(), pcds.size()) << s.name;
    for (std::size_t k = 0; k < pcds.size(); ++k) {
      const Scan want = toScan(readPcd(pcds[k]));
      ASSERT_EQ(got[k].size(), want.size()) << pcds[k];
      for (std::size_t i = 0; i < want.size(); ++i) {
        ASSERT_EQ(got[k].x[i], want.x[i]) << pcds[k] << " point " << i;
        ASSERT_EQ(got[k].z[i], want.z[i]);
        ASSERT_EQ(got[k].ring[i], want.ring[i]);
        ASSERT_EQ(got[k].offset_ns[i], want.offset_ns[i]) << pcds[k] << " point " << i;  // PCD keeps no stamp
      }
    }
  }
  // /tf_static: base_link -> every lidar.
  ASSERT_EQ(tf.size(), std::size(kSensors));
  for (const auto& t : tf) EXPECT_EQ(t.parent_frame, "base_link");
  // /odom: poses.csv's rows (timestamp_ns, index, px, py, pz, ...).
  std::ifstream csv(sim / "poses.csv");
  std::vector<std::pair<TimeNs, Eigen::Vector3d>> rows;
  for (std::string line; std::getline(csv, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    TimeNs t;
    long index;
    char comma;
    Eigen::Vector3d p;
    in >> t >> comma >> index >> comma >> p.x() >> comma >> p.y() >> comma >> p.z();
    rows.emplace_back(t, p);
  }
  ASSERT_FALSE(rows.empty());
  ASSERT_EQ(odometry.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(odometry[i].first, rows[i].first) << i;
    EXPECT_EQ(odometry[i].second, rows[i].second) << i;
  }
}

// rig-from-bag on the packet form: every sensor with its model (from the packets) and topic, and the
// initial extrinsics from /tf_static equal to the sim's rig.yaml.
TEST_F(SimBag, RigFromBagNamesEverySensorModelTopicAndExtrinsic) {
  ASSERT_EQ(sim_->exit_code, 0) << sim_->err;
  const fs::path sim = dir_->path() / "sim";
  const auto r = runRigcal({"rig-from-bag", (sim / "recording.mcap").string(), "--out", (dir_->path() / "from_bag.yaml").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node got = YAML::LoadFile((dir_->path() / "from_bag.yaml").string());
  const YAML::Node want = YAML::LoadFile((sim / "rig.yaml").string());
  ASSERT_EQ(got["sensors"].size(), std::size(kSensors));
  for (std::size_t i = 0; i < std::size(kSensors); ++i) {
    const YAML::Node s = got["sensors"][i];
    const std::string name = s["name"].as<std::string>();
    EXPECT_EQ(name, kSensors[i].name);
    EXPECT_EQ(s["model"].as<std::string>(), kSensors[i].model) << name;
    EXPECT_EQ(s["source"]["topic"].as<std::string>(), "/" + name + "/packets");
    for (const char* k : {"x", "y", "z", "roll", "pitch", "yaw"})
      EXPECT_NEAR(got["initial_extrinsics"][name][k].as<double>(), want["initial_extrinsics"][name][k].as<double>(), 2e-6)
          << name << " " << k;
  }
}

// rig-from-bag on the PointCloud2 form: `model: PointCloud2` sensors on the points topics, a rig that
// check-config accepts as written (no decoder, calibration or metadata file to add).
TEST_F(SimBag, RigFromAPointCloud2BagRunsAsWritten) {
  ASSERT_EQ(sim_->exit_code, 0) << sim_->err;
  const fs::path sim = dir_->path() / "sim", rig = dir_->path() / "from_points.yaml";
  const auto r = runRigcal({"rig-from-bag", (sim / "recording_points.mcap").string(), "--out", rig.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node got = YAML::LoadFile(rig.string());
  ASSERT_EQ(got["sensors"].size(), std::size(kSensors));
  for (std::size_t i = 0; i < std::size(kSensors); ++i) {
    const YAML::Node s = got["sensors"][i];
    const std::string name = s["name"].as<std::string>();
    EXPECT_EQ(s["model"].as<std::string>(), "PointCloud2") << name;
    EXPECT_EQ(s["source"]["topic"].as<std::string>(), "/" + name + "/points");
  }
  const auto checked = runRigcal({"check-config", rig.string()});
  EXPECT_EQ(checked.exit_code, 0) << checked.out << checked.err;
}

}  // namespace
}  // namespace rigcal::test
