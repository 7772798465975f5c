// base_link yaw and x from the drive through the real binaries: `rigcal sim --scenario base-motion` (rear-axle
// base_link, a straight, a left and a right turn with stops) → the mapping lidar's initial guess set 0.3 m
// off in x and 5° off in yaw → `rigcal calibrate` with base_link_from_motion: yaw_x → report.json and the
// summary. A straight-only drive estimates yaw and says x is not observable. A drive that stops and backs
// up between its turns still gives both (the estimator flips reversing chords; the mapper's constant-velocity
// model has no preferred direction, and its keyframe check allows the travel direction to flip at a stop).
// Measured (Release, machine at load ~20): turns both ways: x 1.347 m (truth 1.350, σ 4 mm), yaw 1.515°
// (truth 1.500°, σ 0.021°), 47 chords, 23 m straight, 89° left / 89° right; sim 23 s, calibrate 80 s.
// Reversing and stops (Release): x error −0.8 mm (σ 5.0 mm), yaw error −0.004° (σ 0.030°), 5.5 m of the 6.2 m
// backwards used, no frame lost; sim 7 s, calibrate 15 s CPU.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "calibrate_chain.hpp"
#include "sanitizers.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct Truth {
  double x = 0, yaw = 0;
};

/// Reads the mapping lidar's true T_base_sensor and rewrites rig.yaml's initial guess for it: x 0.3 m
/// and yaw 5° off the truth (the rest as the simulator perturbed it).
Truth offsetGuess(const std::filesystem::path& sim) {
  const YAML::Node truth = YAML::LoadFile((sim / "truth.yaml").string())["sensors"]["top"]["T_base_sensor"];
  Truth t{truth["x"].as<double>(), truth["yaw"].as<double>()};
  std::string rig = fileContents(sim / "rig.yaml");
  const std::size_t at = rig.find("\n  top: {", rig.find("initial_extrinsics:"));
  EXPECT_NE(at, std::string::npos) << rig;
  if (at == std::string::npos) return t;
  const std::size_t end = rig.find('\n', at + 1);
  const YAML::Node guess = YAML::Load(rig.substr(at + 1, end - at - 1))["top"];
  char line[256];
  std::snprintf(line, sizeof line, "\n  top: {x: %.9f, y: %.9f, z: %.9f, roll: %.9f, pitch: %.9f, yaw: %.9f}",
                t.x + 0.3, guess["y"].as<double>(), guess["z"].as<double>(), guess["roll"].as<double>(),
                guess["pitch"].as<double>(), t.yaw + 5.0 * kDeg);
  rig.replace(at, end - at, line);
  std::ofstream(sim / "rig.yaml") << rig;
  return t;
}

/// What a calibration of the simulated drive gave, from the guess offsetGuess() set.
struct MotionRun {
  Truth truth;
  CommandResult calibrated;
  nlohmann::json report;
};

/// Sets the guess off (offsetGuess), runs `rigcal calibrate` on `sim` into `out`, expects success.
void calibrateFromOffsetGuess(const std::filesystem::path& sim, const std::filesystem::path& out, MotionRun& run) {
  run.truth = offsetGuess(sim);
  run.calibrated = runRigcal(calibrateArgs(sim, out));
  std::printf("%s", run.calibrated.out.c_str());
  ASSERT_EQ(run.calibrated.exit_code, 0) << run.calibrated.out << run.calibrated.err;
  run.report = readJson(out / "report.json");
}

/// Yaw within 0.1° and x within 5 cm, both from the motion, with turns of more than 45° each way.
void expectYawAndXFromMotion(const MotionRun& run, const char* what) {
  const auto& base = run.report["base_lidar"];
  ASSERT_TRUE(base.contains("motion")) << base.dump(2);
  const auto& m = base["motion"];
  ASSERT_TRUE(m["yaw_deg"]["estimated"].get<bool>()) << m.dump(2);
  ASSERT_TRUE(m["x_m"]["estimated"].get<bool>()) << m.dump(2);
  const double yaw_err = m["yaw_deg"]["value"].get<double>() - run.truth.yaw / kDeg;
  const double x_err = m["x_m"]["value"].get<double>() - run.truth.x;
  std::printf("%s, from 0.3 m / 5 deg off: yaw error %.4f deg (std %.4f), x error %.4f m (std %.4f)\n", what,
              yaw_err, m["yaw_deg"]["stddev"].get<double>(), x_err, m["x_m"]["stddev"].get<double>());
  EXPECT_LT(std::abs(yaw_err), 0.1);
  EXPECT_LT(std::abs(x_err), 0.05);
  EXPECT_GT(m["left_turn_deg"].get<double>(), 45.0);
  EXPECT_GT(m["right_turn_deg"].get<double>(), 45.0);
  EXPECT_EQ(base["sources"]["x"], "motion");
  EXPECT_EQ(base["sources"]["yaw"], "motion");
  EXPECT_NEAR(run.report["T_base_sensor"]["top"]["x"].get<double>(), run.truth.x, 0.05);
  EXPECT_NEAR(run.report["T_base_sensor"]["top"]["yaw"].get<double>(), run.truth.yaw, 0.1 * kDeg);
}

TEST(BaseFromMotionCli, TurnsBothWaysGiveYawAndX) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation and calibration of a drive: Release only";
  TempDir dir;
  const auto sim = dir / "sim", out = dir / "out";
  ASSERT_NO_FATAL_FAILURE(simulate("base-motion", sim));
  MotionRun run;
  ASSERT_NO_FATAL_FAILURE(calibrateFromOffsetGuess(sim, out, run));
  expectYawAndXFromMotion(run, "turns both ways");
  const auto& base = run.report["base_lidar"];
  EXPECT_EQ(base["sources"]["y"], "guess");
  EXPECT_EQ(base["sources"]["z"], "ground");
  EXPECT_NE(fileContents(out / "calibration.yaml").find("top"), std::string::npos);
  const std::string& printed = run.calibrated.out;
  EXPECT_NE(printed.find("z, roll, pitch from the ground"), std::string::npos) << printed;
  EXPECT_NE(printed.find("from motion"), std::string::npos) << printed;
  EXPECT_NE(printed.find("y from the guess"), std::string::npos) << printed;
}

TEST(BaseFromMotionCli, StraightDriveGivesYawAndSaysXIsNotObservable) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation and calibration of a drive: Release only";
  TempDir dir;
  const auto sim = dir / "sim", out = dir / "out";
  const std::string text = shortenedPreset("base-motion",
                                           "    - {type: stop, duration: 1.0}\n"
                                           "    - {type: accelerate, to_kmh: 10, duration: 2.5}\n"
                                           "    - {type: cruise, duration: 4.5}\n",
                                           // ~16 m of drive: the footprint crop holds a few hundred points.
                                           "    base_lidar_min_plane_points: 300\n");
  ASSERT_FALSE(text.empty());
  ASSERT_NO_FATAL_FAILURE(simulateYaml(text, sim));
  MotionRun run;
  ASSERT_NO_FATAL_FAILURE(calibrateFromOffsetGuess(sim, out, run));
  const auto& report = run.report;
  const auto& calibrated = run.calibrated;
  const auto& m = report["base_lidar"]["motion"];
  ASSERT_TRUE(m["yaw_deg"]["estimated"].get<bool>()) << m.dump(2);
  const double yaw_err = m["yaw_deg"]["value"].get<double>() - run.truth.yaw / kDeg;
  std::printf("straight only, from 5 deg off: yaw error %.4f deg (std %.4f), %.1f m straight\n", yaw_err,
              m["yaw_deg"]["stddev"].get<double>(), m["straight_m"].get<double>());
  EXPECT_LT(std::abs(yaw_err), 0.1);
  EXPECT_FALSE(m["x_m"]["estimated"].get<bool>());
  EXPECT_NE(m["x_m"]["note"].get<std::string>().find("not observable"), std::string::npos) << m.dump(2);
  EXPECT_EQ(report["base_lidar"]["sources"]["x"], "guess");
  EXPECT_NE(calibrated.out.find("x from the guess (not observable"), std::string::npos) << calibrated.out;
}

TEST(BaseFromMotionCli, ReversingAndStopsStillPass) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation and calibration of a drive: Release only";
  TempDir dir;
  const auto sim = dir / "sim", out = dir / "out";
  // A left turn, a stop, ~6 m backwards at 6 km/h, a stop, a right turn: 28 s, 46 m. The first stretch's
  // length puts the mapper's last keyframe before each stop > 0.5 m from it, so its keyframe check sees the
  // direction of travel flip by 180° across the stopped keyframe (allowed from rest, not lost).
  const std::string text = shortenedPreset("base-motion",
                                           "    - {type: stop, duration: 1.0}\n"
                                           "    - {type: accelerate, to_kmh: 10, duration: 2.85}\n"
                                           "    - {type: turn, turn_deg: 90, duration: 5.0}\n"
                                           "    - {type: decelerate, to_kmh: 0, duration: 2.0}\n"
                                           "    - {type: stop, duration: 1.0}\n"
                                           "    - {type: accelerate, to_kmh: -6, duration: 2.0}\n"
                                           "    - {type: cruise, duration: 2.0}\n"
                                           "    - {type: decelerate, to_kmh: 0, duration: 1.5}\n"
                                           "    - {type: stop, duration: 1.0}\n"
                                           "    - {type: accelerate, to_kmh: 10, duration: 2.0}\n"
                                           "    - {type: turn, turn_deg: -90, duration: 5.0}\n"
                                           "    - {type: decelerate, to_kmh: 0, duration: 2.0}\n"
                                           "    - {type: stop, duration: 0.5}\n",
                                           "");
  ASSERT_FALSE(text.empty());
  ASSERT_NO_FATAL_FAILURE(simulateYaml(text, sim));
  MotionRun run;
  ASSERT_NO_FATAL_FAILURE(calibrateFromOffsetGuess(sim, out, run));
  EXPECT_EQ(run.report["input"]["lost_frames"], "0") << "the mapper tracks through the stops and backwards";
  const auto& m = run.report["base_lidar"]["motion"];
  std::printf("reversing %.1f m\n", m["reversing_m"].get<double>());
  // The simulator drove 6.2 m backwards; the estimator used the moving, tracked part of it.
  EXPECT_GT(m["reversing_m"].get<double>(), 3.0);
  EXPECT_LT(m["reversing_m"].get<double>(), 6.5);
  expectYawAndXFromMotion(run, "reversing and stops");
}

}  // namespace
}  // namespace rigcal::test
