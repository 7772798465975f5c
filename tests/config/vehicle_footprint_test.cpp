// The rig's `vehicle:` footprint derives the base-lidar crop box; upstream's base_lidar_crop_box_*
// names still override it one bound at a time; mistakes are refused on one line with their location.
#include <gtest/gtest.h>

#include <fstream>

#include "rigcal/config/rig_config.hpp"
#include "test_data.hpp"

namespace rigcal::config {
namespace {

const std::string kRig = R"(rig: test
sensors:
  - name: top
    model: VLP-32C
    source: {port: 2368}
roles:
  mapping_lidar: top
)";

class VehicleFootprintTest : public ::testing::Test {
 protected:
  RigConfig load(const std::string& extra) {
    const auto path = dir / "rig.yaml";
    std::ofstream(path) << kRig << extra;
    return loadRigConfig(path);
  }
  std::string errorOf(const std::string& extra) {
    try {
      load(extra);
    } catch (const ConfigError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      return msg;
    }
    ADD_FAILURE() << "expected a ConfigError";
    return {};
  }
  test::TempDir dir;
};

TEST_F(VehicleFootprintTest, DefaultCropBoxIsTheDefaultFootprintsAndParametersAgree) {
  const Parameters p = load("").parameters;
  // 4.5 m x 2.0 m car, base_link 1.0 m ahead of the rear bumper, 0.5 m margin, ground level.
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_min_x, -1.5);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_max_x, 4.0);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_min_y, -1.5);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_max_y, 1.5);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_min_z, -1.0);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_max_z, 0.5);
  // Code that builds Parameters{} directly gets the same box as a rig file without `vehicle:`.
  Parameters derived;
  setCropBoxFromFootprint(VehicleFootprint{}, derived);
  const Parameters plain;
  EXPECT_DOUBLE_EQ(plain.base_lidar_crop_box_min_x, derived.base_lidar_crop_box_min_x);
  EXPECT_DOUBLE_EQ(plain.base_lidar_crop_box_max_x, derived.base_lidar_crop_box_max_x);
  EXPECT_DOUBLE_EQ(plain.base_lidar_crop_box_min_y, derived.base_lidar_crop_box_min_y);
  EXPECT_DOUBLE_EQ(plain.base_lidar_crop_box_max_y, derived.base_lidar_crop_box_max_y);
  EXPECT_DOUBLE_EQ(plain.base_lidar_crop_box_min_z, derived.base_lidar_crop_box_min_z);
  EXPECT_DOUBLE_EQ(plain.base_lidar_crop_box_max_z, derived.base_lidar_crop_box_max_z);
}

TEST_F(VehicleFootprintTest, VehicleSectionDerivesTheBoxAndUpstreamNamesOverrideOneBound) {
  const RigConfig rig = load("vehicle: {length: 12.0, width: 2.5, rear_overhang: 3.0}\n"
                             "parameters:\n  base_lidar_crop_box_max_z: 0.2\n");
  EXPECT_DOUBLE_EQ(rig.vehicle.length, 12.0);
  const Parameters& p = rig.parameters;
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_min_x, -3.5);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_max_x, 9.5);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_min_y, -1.75);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_max_y, 1.75);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_min_z, -1.0);
  EXPECT_DOUBLE_EQ(p.base_lidar_crop_box_max_z, 0.2);  // named: kept
  // Upstream's wide box, all six by name, is still accepted as it is.
  const Parameters wide = load("parameters: {base_lidar_crop_box_min_x: -20, base_lidar_crop_box_max_x: 20, "
                               "base_lidar_crop_box_min_y: -20, base_lidar_crop_box_max_y: 20, "
                               "base_lidar_crop_box_min_z: -20, base_lidar_crop_box_max_z: 20}\n")
                              .parameters;
  EXPECT_DOUBLE_EQ(wide.base_lidar_crop_box_min_x, -20.0);
  EXPECT_DOUBLE_EQ(wide.base_lidar_crop_box_max_z, 20.0);
}

TEST_F(VehicleFootprintTest, MistakesAreNamedWithTheirLocation) {
  const std::string unknown = errorOf("vehicle: {lenght: 4.0}\n");
  EXPECT_NE(unknown.find("rig.yaml:8:"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("did you mean 'length'"), std::string::npos) << unknown;
  const std::string negative = errorOf("vehicle: {width: -2}\n");
  EXPECT_NE(negative.find("'width'"), std::string::npos) << negative;
  EXPECT_NE(negative.find("allowed"), std::string::npos) << negative;
  const std::string text = errorOf("vehicle: {length: nan}\n");
  EXPECT_NE(text.find("'length' must be a finite number"), std::string::npos) << text;
  const std::string behind = errorOf("vehicle: {length: 4.0, rear_overhang: 5.0}\n");
  EXPECT_NE(behind.find("rear_overhang"), std::string::npos) << behind;
  const std::string inverted = errorOf("parameters: {base_lidar_crop_box_min_y: 3.0}\n");
  EXPECT_NE(inverted.find("base_lidar_crop_box_min_y (3) must be below base_lidar_crop_box_max_y (1.5)"),
            std::string::npos)
      << inverted;
  EXPECT_NE(errorOf("vehicle: [4.5, 2.0]\n").find("vehicle must be a mapping"), std::string::npos);
}

}  // namespace
}  // namespace rigcal::config
