// `rigcal rig-from-bag` on the real packet bags of ../shared/data/bags: the inspect listing, then a
// starter rig naming the packet topic and the model the packets say (Velodyne factory byte, Hesai
// layout, RoboSense MSOP), written atomically with --out; a bag without lidar topics is exit 5.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

struct RealBag {
  const char* folder;
  const char* topic;
  const char* model;
};

TEST(RigFromBag, RealPacketBagsGiveTheirTopicAndModel) {
  for (const RealBag& b : {RealBag{"nebula_vlp32", "/sensing/lidar/front/velodyne_packets", "VLP-32C"},
                           RealBag{"nebula_xt32", "/pandar_packets", "PandarXT32"},
                           RealBag{"nebula_pandar64", "/pandar_packets", "Pandar64"},
                           RealBag{"robosense_helios16p", "/robosense_packets", "RS-Helios-16P"}}) {
    RIGCAL_REQUIRE_DATA(bag, std::string("bags/") + b.folder);
    TempDir dir;
    const auto r = runRigcal({"rig-from-bag", bag.string(), "--out", (dir / "rig.yaml").string()});
    ASSERT_EQ(r.exit_code, 0) << b.folder << ": " << r.err;
    EXPECT_NE(r.out.find("topic "), std::string::npos) << "the inspect listing comes first";
    EXPECT_NE(r.out.find("wrote " + (dir / "rig.yaml").string()), std::string::npos) << r.out;
    const YAML::Node rig = YAML::LoadFile((dir / "rig.yaml").string());
    ASSERT_EQ(rig["sensors"].size(), 1u) << b.folder;
    const YAML::Node s = rig["sensors"][0];
    EXPECT_EQ(s["model"].as<std::string>(), b.model) << b.folder;
    EXPECT_EQ(s["source"]["topic"].as<std::string>(), b.topic) << b.folder;
    EXPECT_EQ(rig["roles"]["mapping_lidar"].as<std::string>(), s["name"].as<std::string>());
    EXPECT_EQ(rig["roles"]["base_frame"].as<std::string>(), "base_link");
    EXPECT_TRUE(rig["initial_extrinsics"][s["name"].as<std::string>()]["yaw"]) << b.folder;
  }
}

TEST(RigFromBag, ABagWithoutLidarTopicsIsNotEnoughData) {
  RIGCAL_REQUIRE_DATA(bag, "bags/rosbag2/mcap_talker");
  TempDir dir;
  const auto r = runRigcal({"rig-from-bag", bag.string(), "--out", (dir / "rig.yaml").string()});
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_NE(r.err.find("no lidar topic"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "rig.yaml"));
}

}  // namespace
}  // namespace rigcal::test
