// Issue 19's unusual mounts through the real binaries, as a user meets them: `rigcal sim --scenario
// yard-corners|yard-side` → `rigcal calibrate` (the preset's rig: guesses 0.3 m / 5° off, default parameters
// plus calibrate_base_frame: true) → `rigcal compare` against truth.yaml.
//   yard-corners: VLP-32C maps; VLP-16 corners yawed ±45° and pitched 15° down; a rear VLP-16 yawed 180°
//                 and pitched 20° down (16 beams against a 32-beam map).
//   yard-side:    OS1-64 maps; a VLP-32C rolled 90° and a VLP-16 rolled −90° (spin axes horizontal).
// With the default deadline the result depends on the machine's load, so what is asserted is honesty: a
// lidar called `ok` is within 1 cm / 0.05°, any other is `unverified` with the --deadline that would do.
// With --deadline 60 every calibration lidar must be within the goal. Each preset is simulated once (~60-90 s)
// and calibrated twice (~2 min each on a loaded machine): RIGCAL_LONG_TESTS=1 (Release) only; 8.1 min for all
// four in one process at load 7-14 on 2 cores (the other helpers' builds).
// Measured with `rigcal calibrate` on the presets (error cm / deg, verdict; frames registered / selected), branch
// s12-mounts against main 849995b, both on the same recordings, offline, nice 15, machine loaded by other builds:
//   --deadline 60    before  yard-corners  corner_left 0.30 / 0.004 ok, corner_right 0.26 / 0.013 unverified (a
//                            trajectory clock +18.9 ± 8.9 ms read off a flat profile), rear 0.27 / 0.005 unverified
//                            (its frames in the turns, deskewed with the guess, 0.1° either side: ± 0.62 cm, 0.068°)
//                            yard-side     side_left 0.09 / 0.015 unverified (one frame 4.1 cm off along its spin
//                            axis, which it does not see: ± 2.44 cm), side_right 0.31 / 0.009 unverified (± 1.01 cm)
//                    after   yard-side (load 6-8): side_left 0.09 / 0.015 ok (± 0.68 cm, each frame's scatter
//                            weighted by its information), side_right 0.31 / 0.009 ok. yard-corners (load 6-7):
//                            corner_left 0.30 / 0.004 ok, rear 0.27 / 0.005 ok (± 0.32 cm, 0.007°), corner_right
//                            0.11 / 0.007 unverified by the same clock reading, which the dip rule then turned into
//                            ± 13.9 ms (ok in a run at load 10-11, where the 20 s shares of the other two were cut
//                            before the re-deskew: rear unverified with the --deadline that would do)
//   default deadline (load 6-10): the plan is cut after 1-2 of 3-5 frames per lidar, before the re-deskew; 0 or 1
//                    lidar ok per preset, each within the goal (rear 0.66 / 0.029 ok on 2 frames); the others
//                    unverified with the --deadline that would do, among them side_left 42 cm off on its one frame
//                    (a straight stretch: blind along its spin axis). Never a wrong ok.
// The default deadline is not reliably within the goal on a loaded machine (the registrations of one frame take
// most of a 3-5 s share), so UnderTheDefaultDeadline asserts honesty only.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "calibrate_chain.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

struct LidarError {
  double cm = -1, deg = -1;
};

/// `rigcal compare`'s "error X cm Y deg" of each T_<mapping>_<sensor> block, by sensor.
std::map<std::string, LidarError> lidarErrors(const std::string& compare_out, const nlohmann::json& lidars) {
  std::map<std::string, LidarError> errors;
  std::istringstream in(compare_out);
  std::string line, block;
  while (std::getline(in, line)) {
    if (line.rfind("T_", 0) == 0) block = line.substr(0, line.find(' '));
    const auto at = line.find(" error ");
    if (at == std::string::npos || block.empty()) continue;
    for (const auto& l : lidars) {
      const std::string sensor = l["sensor"].get<std::string>();
      if (block.size() > sensor.size() && block.compare(block.size() - sensor.size(), sensor.size(), sensor) == 0 &&
          block[block.size() - sensor.size() - 1] == '_') {
        std::istringstream nums(line.substr(at + 7));
        std::string unit;
        LidarError e;
        nums >> e.cm >> unit >> e.deg;
        errors[sensor] = e;
      }
    }
  }
  return errors;
}

/// The preset simulated once per test binary run (both tests of a preset share it).
const std::filesystem::path& simulated(const std::string& preset) {
  static std::map<std::string, std::unique_ptr<TempDir>> dirs;
  auto& d = dirs[preset];
  if (!d) {
    d = std::make_unique<TempDir>();
    double seconds = 0;
    simulate(preset, *d / "sim", &seconds);
    std::printf("%s: sim %.1f s\n", preset.c_str(), seconds);
  }
  static std::map<std::string, std::filesystem::path> paths;
  return paths[preset] = *d / "sim";
}

/// calibrate (with `extra` arguments) → compare; every lidar's verdict, frames, registrations and error printed.
struct Calibrated {
  int exit_code = -1;
  nlohmann::json report;
  std::map<std::string, LidarError> errors;
};

Calibrated calibrate(const std::string& preset, const std::vector<std::string>& extra, const TempDir& dir) {
  Calibrated c;
  const auto& sim = simulated(preset);
  if (!std::filesystem::exists(sim / "recording.pcap")) {
    ADD_FAILURE() << "rigcal sim --scenario " << preset << " failed";
    return c;
  }
  const auto out = dir / "out";
  const auto run = runRigcal(calibrateArgs(sim, out, extra));
  c.exit_code = run.exit_code;
  if (!std::filesystem::exists(out / "report.json")) {
    ADD_FAILURE() << "no report.json: " << run.out << run.err;
    return c;
  }
  c.report = readJson(out / "report.json");
  const auto compared = compareWithTruth(sim, out, 1.0, 0.05);
  c.errors = lidarErrors(compared.out, c.report["lidars"]);
  for (const auto& l : c.report["lidars"]) {
    const std::string sensor = l["sensor"].get<std::string>();
    const auto& e = l.value("evidence", nlohmann::json::object());
    std::printf("%s %-13s %-11s error %.3f cm %.4f deg  frames %d/%d  registrations %zu  inliers %.2f  %.1f s\n",
                preset.c_str(), sensor.c_str(), l.value("verdict", "-").c_str(), c.errors[sensor].cm,
                c.errors[sensor].deg, e.value("frames_registered", 0), e.value("frames_selected", 0),
                l.value("registrations", nlohmann::json::array()).size(), e.value("inlier_ratio", 0.0),
                l.value("seconds", 0.0));
  }
  return c;
}

class CalibrateYardLong : public ::testing::TestWithParam<const char*> {};

// The default deadline, whatever the load: never a wrong `ok` — ok → within the goal; otherwise unverified,
// saying what would confirm it (the --deadline, or more frames). Measured since the keyframe-lost check follows
// the vehicle's turns (frame_tracker.cpp; before, side_right got 4 frames and came out 0.89 cm off, unverified):
// quiet and beside one busy loop every lidar of both rigs within the goal, side_right ok at 0.44 cm on 7 frames;
// beside a whole build (load 6) a plan can still be cut to side_left's first frame, blind along the spin axis:
// 42 cm off, unverified with the --deadline that would do.
TEST_P(CalibrateYardLong, UnderTheDefaultDeadlineOkMeansWithinTheGoal) {
  if (!longTests()) GTEST_SKIP() << "long test: set RIGCAL_LONG_TESTS=1 (Release only)";
  TempDir dir;
  const Calibrated c = calibrate(GetParam(), {}, dir);
  ASSERT_FALSE(c.report.is_null());
  ASSERT_GE(c.report["lidars"].size(), 2u);
  bool all_ok = true;
  for (const auto& l : c.report["lidars"]) {
    const std::string sensor = l["sensor"].get<std::string>();
    ASSERT_TRUE(c.errors.count(sensor)) << sensor << " missing from compare's output";
    const LidarError e = c.errors.at(sensor);
    all_ok = all_ok && l.value("verdict", "") == "ok";
    if (l.value("verdict", "") == "ok") {
      EXPECT_LT(e.cm, 1.0) << sensor << " is called ok off the goal";
      EXPECT_LT(e.deg, 0.05) << sensor << " is called ok off the goal";
    } else {
      EXPECT_EQ(l.value("verdict", ""), "unverified") << sensor;
      // What would confirm it: a --deadline when the deadline cut the plan short of evidence; otherwise (every
      // frame registered, frames that scatter more than the goal) more frames.
      const bool more_time = l["evidence"].value("suggested_deadline_s", 0.0) > 0.0;
      const bool more_frames = l.value("doubt", "").find("more frames would narrow it") != std::string::npos;
      EXPECT_TRUE(more_time || more_frames) << sensor << ": say what would confirm it: " << l.value("doubt", "");
    }
  }
  EXPECT_EQ(c.exit_code, all_ok ? 0 : 6) << "exit 6 (unverified) unless every lidar is ok";
}

// Time enough (what the unverified runs suggest): every calibration lidar within 1 cm / 0.05°, and ok.
TEST_P(CalibrateYardLong, WithALongDeadlineEveryLidarWithinTheGoal) {
  if (!longTests()) GTEST_SKIP() << "long test: set RIGCAL_LONG_TESTS=1 (Release only)";
  TempDir dir;
  const Calibrated c = calibrate(GetParam(), {"--deadline", "60"}, dir);
  ASSERT_FALSE(c.report.is_null());
  for (const auto& l : c.report["lidars"]) {
    const std::string sensor = l["sensor"].get<std::string>();
    ASSERT_TRUE(c.errors.count(sensor)) << sensor << " missing from compare's output";
    EXPECT_LT(c.errors.at(sensor).cm, 1.0) << sensor;
    EXPECT_LT(c.errors.at(sensor).deg, 0.05) << sensor;
    EXPECT_EQ(l.value("verdict", ""), "ok") << sensor << ": " << l.value("doubt", "");
  }
  EXPECT_EQ(c.exit_code, 0);
}

INSTANTIATE_TEST_SUITE_P(Yard, CalibrateYardLong, ::testing::Values("yard-corners", "yard-side"),
                         [](const ::testing::TestParamInfo<const char*>& p) {
                           return std::string(p.param) == "yard-corners" ? "Corners" : "Side";
                         });

}  // namespace
}  // namespace rigcal::test
