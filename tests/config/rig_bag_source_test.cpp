// The rig file's bag fields: a sensor's source may be a bag topic (with its tf frame) instead of a port,
// and initial_extrinsics may be `from_bag` for the whole rig or per sensor.
#include <gtest/gtest.h>

#include <fstream>

#include "rigcal/config/rig_config.hpp"
#include "test_data.hpp"

namespace rigcal::config {
namespace {

RigConfig load(const test::TempDir& dir, const std::string& text) {
  std::ofstream(dir / "rig.yaml") << text;
  return loadRigConfig(dir / "rig.yaml");
}

std::string errorOf(const test::TempDir& dir, const std::string& text) {
  try {
    load(dir, text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

const std::string kSensors = R"(rig: bag
sensors:
  - name: top
    model: PointCloud2
    source: {topic: /sensing/lidar/top/pointcloud_raw, frame: velodyne_top}
  - name: left
    model: VLP-16
    source: {topic: /sensing/lidar/left/velodyne_packets}
  - name: right
    model: VLP-16
    source: {port: 2368, topic: /right/packets}
roles:
  mapping_lidar: top
  calibration_lidars: [left, right]
)";

TEST(RigBagSource, ATopicIsASourceWithoutPortAndSensorsWithoutPortsDoNotClash) {
  test::TempDir dir;
  const RigConfig rig = load(dir, kSensors);
  EXPECT_EQ(rig.sensor("top").source.topic.value_or(""), "/sensing/lidar/top/pointcloud_raw");
  EXPECT_EQ(rig.sensor("top").source.frame.value_or(""), "velodyne_top");
  EXPECT_EQ(rig.sensor("top").source.port, 0);
  EXPECT_EQ(rig.sensor("left").source.port, 0) << "two topic-only sensors share no port";
  EXPECT_EQ(rig.sensor("right").source.port, 2368);
  EXPECT_TRUE(rig.extrinsics_from_bag.empty());
}

TEST(RigBagSource, InitialExtrinsicsFromBagForTheRigOrPerSensor) {
  test::TempDir dir;
  EXPECT_EQ(load(dir, kSensors + "initial_extrinsics: from_bag\n").extrinsics_from_bag,
            (std::vector<std::string>{"top", "left", "right"}));
  const RigConfig per = load(dir, kSensors + "initial_extrinsics:\n  left: from_bag\n  top: {x: 1.5}\n");
  EXPECT_EQ(per.extrinsics_from_bag, (std::vector<std::string>{"left"}));
  EXPECT_DOUBLE_EQ(per.initial_T_base_sensor.at("top").translation().x(), 1.5);
}

TEST(RigBagSource, MistakesAreOneLineWithTheirPlace) {
  test::TempDir dir;
  const std::string no_port = errorOf(dir, R"(sensors:
  - name: top
    model: VLP-16
    source: {address: 10.0.0.1}
roles: {mapping_lidar: top}
)");
  EXPECT_NE(no_port.find("rig.yaml:4:"), std::string::npos) << no_port;
  EXPECT_NE(no_port.find("'port'"), std::string::npos) << no_port;
  EXPECT_NE(no_port.find("(or a bag 'topic')"), std::string::npos) << no_port;
  const std::string bad = errorOf(dir, kSensors + "initial_extrinsics: from_tf\n");
  EXPECT_NE(bad.find("'initial_extrinsics' must be a mapping of sensor names or 'from_bag', got 'from_tf'"),
            std::string::npos) << bad;
  const std::string key = errorOf(dir, R"(sensors:
  - name: top
    model: VLP-16
    source: {topics: /a}
roles: {mapping_lidar: top}
)");
  EXPECT_NE(key.find("topics"), std::string::npos) << key;
}

}  // namespace
}  // namespace rigcal::config
