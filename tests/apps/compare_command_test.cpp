// `rigcal compare` through the real binary: a calibration next to a simulation's truth, errors measured
// on what each calibration determines, and --max-cm / --max-deg as a pass/fail gate.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iomanip>

#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

class CompareCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    // Truth: top at (1, 0, 2) level; left at (1, 0.8, 1.9) yawed 30° (0.5235987756 rad).
    std::ofstream(dir_ / "truth.yaml")
        << "scenario: test\nbase_frame: base_link\nmapping_lidar: top\ncalibration_lidars: [left]\nsensors:\n"
           "  top:\n    model: OS1-64\n    T_base_sensor: {x: 1.0, y: 0.0, z: 2.0, roll: 0.0, pitch: 0.0, yaw: 0.0}\n"
           "  left:\n    model: VLP-16\n"
           "    T_base_sensor: {x: 1.0, y: 0.8, z: 1.9, roll: 0.0, pitch: 0.0, yaw: 0.5235987756}\n";
  }
  // A calibration.yaml whose left lidar is `dx` metres and `dyaw` radians off; the whole rig is moved up `dz`
  // and turned by `dyaw_top` about the top lidar's z axis.
  std::string result(double dx, double dyaw, double dz, double dyaw_top = 0.0) {
    const auto path = dir_ / "calibration.yaml";
    const double left_x = 1.0 + dx - 0.8 * std::sin(dyaw_top), left_y = 0.8 * std::cos(dyaw_top);
    std::ofstream(path) << "T_base_sensor:\n"
                        << "  top: {x: 1.0, y: 0.0, z: " << 2.0 + dz << ", roll: 0, pitch: 0, yaw: " << dyaw_top
                        << "}\n"
                        << std::setprecision(10) << "  left: {x: " << left_x << ", y: " << left_y
                        << ", z: " << 1.9 + dz
                        << ", roll: 0, pitch: 0, yaw: " << 0.5235987756 + dyaw + dyaw_top << "}\n";
    return path.string();
  }
  std::vector<std::string> args(const std::string& result_path) {
    return {"compare", "--truth", (dir_ / "truth.yaml").string(), "--result", result_path};
  }
  TempDir dir_;
};

TEST_F(CompareCommand, ReportsTheErrorOfEachCalibration) {
  const CommandResult r = runRigcal(args(result(0.02, 0.001, 0.0)));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("T_top_left"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("error 2.000 cm 0.057 deg"), std::string::npos) << r.out;  // 0.001 rad = 0.0573°
  EXPECT_NE(r.out.find("z/roll/pitch error 0.000 cm 0.000 deg"), std::string::npos) << r.out;
}

TEST_F(CompareCommand, TheMappingLidarIsJudgedOnZRollPitchOnly) {
  // The same rig moved up 1 cm and turned 10° about z: the lidar-lidar result is unchanged, only the
  // base-lidar z error shows; the yaw the ground cannot see is not counted.
  const CommandResult r = runRigcal(args(result(0.0, 0.0, 0.01, 0.1745)));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("error 0.000 cm 0.000 deg"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("z/roll/pitch error 1.000 cm 0.000 deg"), std::string::npos) << r.out;
}

TEST_F(CompareCommand, ToleranceGatesTheExitCode) {
  auto within = args(result(0.005, 0.0005, 0.0));
  within.insert(within.end(), {"--max-cm", "1", "--max-deg", "0.05"});
  const CommandResult ok = runRigcal(within);
  EXPECT_EQ(ok.exit_code, 0) << ok.out << ok.err;
  EXPECT_NE(ok.out.find("every error within 1 cm / 0.05 deg"), std::string::npos) << ok.out;

  auto outside = args(result(0.02, 0.0, 0.0));
  outside.insert(outside.end(), {"--max-cm", "1"});
  const CommandResult bad = runRigcal(outside);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("calibration error above 1 cm"), std::string::npos) << bad.err;
}

TEST_F(CompareCommand, WrongFilesAreOneLineErrors) {
  const CommandResult swapped = runRigcal({"compare", "--truth", result(0, 0, 0), "--result", result(0, 0, 0)});
  EXPECT_EQ(swapped.exit_code, 4);
  EXPECT_NE(swapped.err.find("not a rigcal sim truth.yaml"), std::string::npos) << swapped.err;

  std::ofstream(dir_ / "partial.yaml") << "T_base_sensor:\n  top: {x: 1, y: 0, z: 2, roll: 0, pitch: 0, yaw: 0}\n";
  const CommandResult missing = runRigcal(args((dir_ / "partial.yaml").string()));
  EXPECT_EQ(missing.exit_code, 4);
  EXPECT_NE(missing.err.find("T_base_sensor has no 'left'"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace rigcal::test
