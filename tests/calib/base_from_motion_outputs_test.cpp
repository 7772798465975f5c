// The base_link row's sources in report.json and the summary: ground, motion or guess per component.
#include <gtest/gtest.h>

#include "rigcal/calib/outputs/report_json_writer.hpp"
#include "rigcal/calib/outputs/summary_table.hpp"

namespace rigcal::calib {
namespace {

CalibrationOutcome outcomeWithBase() {
  CalibrationOutcome o;
  o.mapping_sensor = "top";
  o.initial_T_base_sensor["top"] = fromXyzRpy({1.5, 0.0, 2.0, 0, 0, 0.08});
  BaseLidarResult base;
  base.ok = true;
  base.T_base_lidar = fromXyzRpy({1.2, 0.0, 1.98, 0.01, -0.02, 0.03});
  o.base = base;
  return o;
}

TEST(BaseFromMotionOutputs, GroundOnlySaysXYYawCameFromTheGuess) {
  const auto o = outcomeWithBase();
  const auto j = reportJson(o);
  EXPECT_EQ(j["base_lidar"]["sources"]["z"], "ground");
  EXPECT_EQ(j["base_lidar"]["sources"]["yaw"], "guess");
  EXPECT_EQ(j["base_lidar"]["sources"]["x"], "guess");
  EXPECT_FALSE(j["base_lidar"].contains("motion"));
  EXPECT_NE(summaryTable(o).find("x, y, yaw from the guess (base_link_from_motion: off)"), std::string::npos);
}

TEST(BaseFromMotionOutputs, MotionPartsAreNamedWithTheirSupport) {
  auto o = outcomeWithBase();
  BaseFromMotionResult m;
  m.yaw = {true, 0.03, 0.0005, ""};
  m.x = {false, 1.5, 0.0, "not observable: turns 40 deg left, 0 deg right (need 20 deg each way); kept the guess"};
  m.straight_m = 18.5;
  m.left_turn_deg = 40;
  o.base_motion = m;
  const auto j = reportJson(o);
  EXPECT_EQ(j["base_lidar"]["sources"]["yaw"], "motion");
  EXPECT_EQ(j["base_lidar"]["sources"]["x"], "guess");
  EXPECT_EQ(j["base_lidar"]["sources"]["y"], "guess");
  EXPECT_NEAR(j["base_lidar"]["motion"]["yaw_deg"]["value"].get<double>(), rad2deg(0.03), 1e-9);
  EXPECT_NEAR(j["base_lidar"]["motion"]["straight_m"].get<double>(), 18.5, 1e-12);
  EXPECT_NE(j["base_lidar"]["motion"]["x_m"]["note"].get<std::string>().find("0 deg right"), std::string::npos);
  const std::string table = summaryTable(o);
  EXPECT_NE(table.find("z, roll, pitch from the ground; yaw 1.719 deg ± 0.029 from motion (18.5 m straight)"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("x from the guess (not observable: turns 40 deg left"), std::string::npos) << table;
}

}  // namespace
}  // namespace rigcal::calib
