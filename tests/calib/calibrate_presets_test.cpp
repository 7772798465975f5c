// Every simulator preset with calibration lidars through the real binaries, as a user runs them:
// `rigcal sim --scenario P` → `rigcal calibrate` from its capture (rig.yaml starts 0.3 m / 5° off) →
// `rigcal compare --max-cm 1 --max-deg 0.05` against truth.yaml: each calibration lidar within 1 cm /
// 0.05° of T_mapping_calib, the mapping lidar's z within 1 cm and roll/pitch within 0.05° of T_base_mapping.
//
// Full-length presets are long (the street preset alone casts 143 M rays): they run with
// RIGCAL_LONG_TESTS=1 (Release). The default suite runs a shorter drive of each preset through the same
// chain (same rig, scene and guesses; parameters scaled to the shorter drive).
// Measured (Release, machine shared at load 6-8), errors after calibration from 0.3 m / 5° guesses:
//   parking-lot  front_left 0.31 cm 0.009°, front_right 0.51 cm 0.013°; base z 0.02 cm, roll/pitch 0.032°
//                (sim 45 s, calibrate 75 s)
//   street       rear 0.10 cm 0.004°, front 0.16 cm 0.000°, left 0.10 cm 0.011°; base 0.03 cm, 0.011°
//                (sim 63 s, calibrate 230 s; lidar-lidar took 120 s of its 60 s deadline, two batches)
//                with one deadline for all lidars: lidar-lidar 60.1 s, 20.0 / 20.0 / 19.9 s shares; rear 0.053 cm
//                0.005°, front 0.20 cm 0.001°, left 0.070 cm 0.007°; base 0.003 cm, 0.009° (sim 62 s,
//                calibrate 137 s, load 4-6); at the default 10 s deadline (the preset's since session 12): every
//                lidar ok (dl), rear 0.10 cm 0.001°, front 0.09-0.37 cm 0.001-0.028°, left 0.15-0.17 cm
//                0.006-0.009° (two runs of calibrate on one capture, load 5-6)
//   lost         front_left 0.25 cm 0.014°; base 0.05 cm, 0.016° (sim 21 s, calibrate 39 s)
// The `pose` preset has no calibration lidar (one VLP-16 and an INS; see calibrate_pose_cli_test.cpp), and
// its ±15° roll / ±12° pitch excitation tilts base_link over the ground on purpose, so base-lidar is not
// defined there.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include "calibrate_chain.hpp"
#include "sanitizers.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

using Clock = std::chrono::steady_clock;

/// sim → calibrate → compare with the bounds; prints the comparison and the stage times. The
/// lidar-lidar stage keeps to calibration_deadline_s as a whole (all calibration lidars together).
/// `whole_plan`: every calibration lidar's plan must also finish inside the deadline (every selected frame's
/// target and ensemble, the batched chain, the re-deskew: `deadline_reached: false`) — a figure of a quiet
/// machine, which is where the long tests run.
void calibratePreset(const std::string& label, const std::string& scenario_arg, const TempDir& dir,
                     bool whole_plan = false) {
  const auto sim = dir / "sim", out = dir / "out";
  double sim_seconds = 0.0;
  ASSERT_NO_FATAL_FAILURE(simulate(scenario_arg, sim, &sim_seconds));
  const auto t0 = Clock::now();
  const auto calibrated = runRigcal(calibrateArgs(sim, out));
  const double calibrate_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf("%s", calibrated.out.c_str());
  ASSERT_EQ(calibrated.exit_code, 0) << calibrated.out << calibrated.err;
  const auto compared = compareWithTruth(sim, out, 1.0, 0.05);
  std::printf("%s\n%s: sim %.1f s, calibrate %.1f s\n", compared.out.c_str(), label.c_str(), sim_seconds,
              calibrate_seconds);
  const auto report = readJson(out / "report.json");
  std::printf("%s stage seconds: %s\n", label.c_str(), report["stage_seconds"].dump().c_str());
  EXPECT_EQ(compared.exit_code, 0) << compared.out << compared.err;
  ASSERT_TRUE(report.contains("base_lidar")) << "the preset calibrates the mapping lidar to base_link";
  EXPECT_TRUE(report["base_lidar"]["ok"].get<bool>()) << report["base_lidar"].dump(2);
  // One deadline for every calibration lidar together, whenever their datasets came (a step that does
  // not fit is not started: the overshoot is a fraction of a step).
  const double deadline = report["deadline_s"].get<double>();
  if (rigcal::test::kWallClockAsserted) {
    EXPECT_LT(report["stage_seconds"]["lidar_lidar"].get<double>(), 1.05 * deadline + 1.0) << report["stage_seconds"];
  }
  if (whole_plan && rigcal::test::kWallClockAsserted) {
    for (const auto& l : report["lidars"]) {
      EXPECT_FALSE(l.value("deadline_reached", true)) << l.value("sensor", "") << ": the deadline cut its plan "
                                                      << l["stage_seconds"].dump();
      const auto& e = l.value("evidence", nlohmann::json::object());
      EXPECT_EQ(e.value("frames_registered", -1), e.value("frames_selected", -2)) << l.value("sensor", "");
    }
  }
}

// The demo: both calibration lidars' whole plans inside the default 10 s (issue 23; 3 of 3 runs on a quiet
// 2-core machine in session 12: 10/10 and 9/9 frames, 0.08 / 0.12 cm).
TEST(CalibratePresetsLong, ParkingLot) {
  if (!longTests()) GTEST_SKIP() << "long test: set RIGCAL_LONG_TESTS=1 (Release only)";
  TempDir dir;
  calibratePreset("parking-lot", "parking-lot", dir, /*whole_plan=*/true);
}

TEST(CalibratePresetsLong, Street) {
  if (!longTests()) GTEST_SKIP() << "long test: set RIGCAL_LONG_TESTS=1 (Release only)";
  TempDir dir;
  calibratePreset("street", "street", dir);
}

TEST(CalibratePresetsLong, Lost) {
  if (!longTests()) GTEST_SKIP() << "long test: set RIGCAL_LONG_TESTS=1 (Release only)";
  TempDir dir;
  calibratePreset("lost", "lost", dir);
}

// The lost preset's first hazard on a 16 s drive: the mapping lidar's 1.5 s outage at 12 s (lost keyframes;
// no frame within dense_pointcloud_num_keyframes of them may be used), with usable stretches before and after.
// Measured 49 s at load 8 (sim 17 s, calibrate 32 s): 0.17 cm / 0.009°, base z 0.07 cm, roll/pitch 0.006°.
TEST(CalibratePresetsShort, Lost) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "simulation and calibration of a drive: Release only";
  TempDir dir;
  const std::string text = shortenedPreset("lost",
                                     "    - {type: accelerate, to_kmh: 5, duration: 2.0}\n"
                                     "    - {type: cruise, duration: 14.0}\n",
                                     "    calibration_skip_keyframes: 1\n"
                                     "    dense_pointcloud_num_keyframes: 3\n"
                                     "    calibration_min_distance_between_frames: 1.5\n"
                                     "    lidar_calibration_max_frames: 4\n");
  ASSERT_FALSE(text.empty());
  std::ofstream(dir / "lost-short.yaml") << text;
  calibratePreset("lost (short)", (dir / "lost-short.yaml").string(), dir);
}

// Not in the default suite: the VLS-128 and three calibration lidars cast ~4 M rays per second of drive,
// so even this 8 s drive takes well over 30 s (sim and the VLS-128 mapping).
TEST(CalibratePresetsLong, StreetShort) {
  if (!longTests()) GTEST_SKIP() << "long test: set RIGCAL_LONG_TESTS=1 (Release only)";
  TempDir dir;
  const std::string text = shortenedPreset("street",
                                     "    - {type: accelerate, to_kmh: 6, duration: 2.0}\n"
                                     "    - {type: cruise, duration: 6.0}\n",
                                     // The roof lidar sees the ground under the car only once the car has
                                     // moved off it: on 11 m of drive the footprint crop holds ~500 points.
                                     "    base_lidar_min_plane_points: 300\n"
                                     "    calibration_deadline_s: 30\n"
                                     "    calibration_skip_keyframes: 1\n"
                                     "    dense_pointcloud_num_keyframes: 3\n"
                                     "    calibration_min_distance_between_frames: 1.5\n"
                                     "    lidar_calibration_max_frames: 4\n");
  ASSERT_FALSE(text.empty());
  std::ofstream(dir / "street-short.yaml") << text;
  calibratePreset("street (short)", (dir / "street-short.yaml").string(), dir);
}

}  // namespace
}  // namespace rigcal::test
