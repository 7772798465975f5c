#include <gtest/gtest.h>

#include <fstream>

#include "rigcal/config/rig_config.hpp"
#include "test_data.hpp"

namespace rigcal::config {
namespace {

class RigConfigTest : public ::testing::Test {
 protected:
  std::filesystem::path write(const std::string& text, const std::string& name = "rig.yaml") {
    const auto path = dir / name;
    std::ofstream(path) << text;
    return path;
  }
  // Loads `text`, expects a ConfigError, and returns its message.
  std::string errorOf(const std::string& text) {
    try {
      loadRigConfig(write(text));
    } catch (const ConfigError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
      return msg;
    }
    ADD_FAILURE() << "expected a ConfigError";
    return {};
  }
  test::TempDir dir;
};

const std::string kMinimal = R"(rig: test
sensors:
  - name: top
    model: VLP-32C
    source: {port: 2368}
  - name: left
    model: VLP-16
    source: {port: 2369, address: 10.0.0.2}
roles:
  mapping_lidar: top
  calibration_lidars: [left]
)";

TEST_F(RigConfigTest, SampleRigsLoad) {
  for (const char* name : {"velodyne-car.yaml"}) {
    const RigConfig rig = loadRigConfig(std::filesystem::path(RIGCAL_RIGS_DIR) / name);
    EXPECT_EQ(rig.roles.mapping_lidar, "top");
    EXPECT_EQ(rig.roles.calibration_lidars.size(), 2u);
    EXPECT_NEAR(toXyzRpy(rig.initial_T_base_sensor.at("front_left")).yaw, 0.7854, 1e-12);
    EXPECT_TRUE(rig.parameters.calibrate_base_frame);
  }
  // The Ouster rig names a metadata file that only exists on the robot: the error says so.
  try {
    loadRigConfig(std::filesystem::path(RIGCAL_RIGS_DIR) / "ouster-hesai-robot.yaml");
    FAIL() << "expected missing metadata";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("os1-64.json"), std::string::npos) << e.what();
  }
}

TEST_F(RigConfigTest, DefaultsAreUpstreamCodeDefaults) {
  const RigConfig rig = loadRigConfig(write(kMinimal));
  const Parameters& p = rig.parameters;
  EXPECT_EQ(p.local_map_num_keyframes, 15);
  EXPECT_EQ(p.new_keyframe_min_distance, 1.0);
  EXPECT_EQ(p.lidar_calibration_max_frames, 10);
  EXPECT_EQ(p.lidar_calibration_min_frames, 2);
  EXPECT_EQ(p.leaf_size_dense_map, 0.05);
  EXPECT_EQ(p.calibration_min_pca_eigenvalue, 0.25);
  EXPECT_EQ(p.max_allowed_interpolated_accel_straight, 0.1);
  EXPECT_EQ(p.lost_frame_max_acceleration, 8.0);
  EXPECT_EQ(rig.sensor("left").source.address, "10.0.0.2");
  EXPECT_TRUE(rig.initial_T_base_sensor.at("top").isApprox(Pose::Identity()));
}

TEST_F(RigConfigTest, ParametersOverrideDefaults) {
  const RigConfig rig = loadRigConfig(write(kMinimal + R"(parameters:
  local_map_num_keyframes: 20
  mapping_registrator: ndt
  crop_z_calibration_pointclouds: false
  leaf_size_dense_map: 0.1
)"));
  EXPECT_EQ(rig.parameters.local_map_num_keyframes, 20);
  EXPECT_EQ(rig.parameters.mapping_registrator, "ndt");
  EXPECT_FALSE(rig.parameters.crop_z_calibration_pointclouds);
  EXPECT_EQ(rig.parameters.leaf_size_dense_map, 0.1);
}

TEST_F(RigConfigTest, UnknownParameterNamesClosestAndLocation) {
  const std::string msg = errorOf(kMinimal + "parameters:\n  local_map_num_keyframe: 20\n");
  EXPECT_NE(msg.find("rig.yaml:13:3:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown parameter 'local_map_num_keyframe'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("did you mean 'local_map_num_keyframes'"), std::string::npos) << msg;
}

TEST_F(RigConfigTest, UnknownTopLevelAndSensorKeys) {
  EXPECT_NE(errorOf(kMinimal + "paramters: {}\n").find("did you mean 'parameters'"), std::string::npos);
  std::string bad = kMinimal;
  bad.replace(bad.find("    model: VLP-16"), 0, "    modle: x\n");
  EXPECT_NE(errorOf(bad).find("unknown key 'modle' in sensor (did you mean 'model'?)"), std::string::npos);
}

TEST_F(RigConfigTest, WrongTypeNamesLocationAndExpectation) {
  const std::string msg = errorOf(kMinimal + "parameters:\n  new_keyframe_min_distance: far\n");
  EXPECT_NE(msg.find("rig.yaml:13:30:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("must be a finite number, got 'far'"), std::string::npos) << msg;
  EXPECT_NE(errorOf(kMinimal + "parameters:\n  local_map_num_keyframes: 2.5\n").find("must be an integer"),
            std::string::npos);
  EXPECT_NE(errorOf(kMinimal + "parameters:\n  calibration_use_only_stopped: maybe\n").find("true or false"),
            std::string::npos);
}

TEST_F(RigConfigTest, OutOfRangeNamesAllowedRange) {
  const std::string msg = errorOf(kMinimal + "parameters:\n  base_lidar_max_cos_distance: 1.5\n");
  EXPECT_NE(msg.find("rig.yaml:13:32:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("out of range; allowed [0, 1]"), std::string::npos) << msg;
  EXPECT_NE(errorOf(kMinimal + "parameters:\n  mapping_registrator: icp\n").find("allowed: gicp, ndt"),
            std::string::npos);
  std::string port = kMinimal;
  port.replace(port.find("{port: 2368}"), 12, "{port: 70000}");
  EXPECT_NE(errorOf(port).find("allowed [1, 65535]"), std::string::npos);
}

TEST_F(RigConfigTest, InconsistentParametersAreRefused) {
  EXPECT_NE(errorOf(kMinimal + "parameters:\n  lidar_calibration_min_frames: 12\n")
                .find("must not exceed lidar_calibration_max_frames"),
            std::string::npos);
}

TEST_F(RigConfigTest, MissingReferencedFileIsNamed) {
  std::string bad = kMinimal;
  bad.replace(bad.find("    source: {port: 2368}"), 0, "    calibration: VLP32.yaml\n");
  const std::string msg = errorOf(bad);
  EXPECT_NE(msg.find("calibration file 'VLP32.yaml' not found"), std::string::npos) << msg;
  EXPECT_NE(msg.find("rig.yaml:5:18:"), std::string::npos) << msg;
  // The same path resolves once the file exists next to the rig file.
  std::ofstream(dir / "VLP32.yaml") << "lasers: []\n";
  EXPECT_EQ(loadRigConfig(write(bad)).sensor("top").calibration, dir / "VLP32.yaml");
}

TEST_F(RigConfigTest, RolesMustNameSensors) {
  std::string bad = kMinimal;
  bad.replace(bad.find("mapping_lidar: top"), 18, "mapping_lidar: tpo");
  EXPECT_NE(errorOf(bad).find("no sensor named 'tpo' (did you mean 'top'?)"), std::string::npos);
  std::string self = kMinimal;
  self.replace(self.find("[left]"), 6, "[top]");
  EXPECT_NE(errorOf(self).find("cannot also be calibrated"), std::string::npos);
}

TEST_F(RigConfigTest, SyntaxErrorsAndMissingFile) {
  EXPECT_NE(errorOf("sensors: [\n").find("YAML syntax error"), std::string::npos);
  EXPECT_THROW(loadRigConfig(dir / "absent.yaml"), ConfigError);
}

TEST_F(RigConfigTest, IgnoredUpstreamParametersWarnInsteadOfFailing) {
  const RigConfig rig = loadRigConfig(write(kMinimal + "parameters:\n  filter_detections: true\n"));
  ASSERT_EQ(rig.warnings.size(), 1u);
  EXPECT_NE(rig.warnings[0].find("'filter_detections' is not used"), std::string::npos);
}

TEST_F(RigConfigTest, InfoPortBringsASecondPortOfTheSameSensor) {
  const std::string rig = R"(rig: test
sensors:
  - name: top
    model: RS-Helios-16P
    source: {port: 6699, info_port: 7788}
roles:
  mapping_lidar: top
)";
  const RigConfig loaded = loadRigConfig(write(rig));
  ASSERT_TRUE(loaded.sensor("top").source.info_port.has_value());
  EXPECT_EQ(*loaded.sensor("top").source.info_port, 7788);
  EXPECT_FALSE(loadRigConfig(write(kMinimal)).sensor("top").source.info_port.has_value());
  std::string bad = rig;
  bad.replace(bad.find("7788"), 4, "70000");
  EXPECT_NE(errorOf(bad).find("info_port"), std::string::npos);
}


// A sensor's time_offset_ns: nanoseconds its clock runs ahead of the rig's (within a minute), or `estimate`.
TEST_F(RigConfigTest, TimeOffsetIsNanosecondsOrEstimate) {
  std::string given = kMinimal;
  given.replace(given.find("    source: {port: 2369"), 0, "    time_offset_ns: -35000000\n");
  const RigConfig g = loadRigConfig(write(given));
  EXPECT_EQ(g.sensor("left").time_offset_ns, -35'000'000);
  EXPECT_FALSE(g.sensor("left").estimate_time_offset);
  EXPECT_EQ(g.sensor("top").time_offset_ns, 0);

  std::string estimated = kMinimal;
  estimated.replace(estimated.find("    source: {port: 2369"), 0, "    time_offset_ns: estimate\n");
  EXPECT_TRUE(loadRigConfig(write(estimated)).sensor("left").estimate_time_offset);

  std::string words = kMinimal;
  words.replace(words.find("    source: {port: 2369"), 0, "    time_offset_ns: 35ms\n");
  EXPECT_NE(errorOf(words).find("'time_offset_ns' must be an integer (nanoseconds) or 'estimate'"), std::string::npos);
  std::string far = kMinimal;
  far.replace(far.find("    source: {port: 2369"), 0, "    time_offset_ns: 3600000000000\n");
  EXPECT_NE(errorOf(far).find("'time_offset_ns' = "), std::string::npos);
}

}  // namespace
}  // namespace rigcal::config
