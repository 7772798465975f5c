// Issue 19's unusual mounts through the real binaries, as a user meets them: `rigcal sim --scenario
// yard-corners|yard-side` → `rigcal calibrate` (the preset's rig: guesses 0.3 m / 5° off, default parameters
// plus calibrate_base_frame: true) → `rigcal compare` against truth.yaml.
//   yard-corners: VLP-32C maps; VLP-16 corners yawed ±45° and pitched 15° down; a rear VLP-16 yawed 180°
//                 and pitched 20° down (16 beams against a 32-beam map).
//   yard-side:    OS1-64 maps; a VLP-32C rolled 90° and a VLP-16 rolled −90° (spin axes horizontal).
// At the default deadline (Release): every calibration lidar within 1 cm / 0.05°, the verdict honest. With
// --deadline 60 (RIGCAL_LONG_TESTS=1): every lidar within the goal and ok. Each preset is simulated once per
// process (~25 s) and calibrated in ~30 s on a quiet machine, ~60 s beside a busy loop.
// Measured (main e8ab3eb, `rigcal calibrate`, error cm / deg, verdict, frames registered / selected):
//   quiet            side_left 0.11 / 0.021 ok 8/8, side_right 0.50 / 0.007 ok 7/7; corner_left 0.11 / 0.005,
//                    corner_right 0.05 / 0.001, rear 0.18 / 0.003, all ok on every frame
//   ctest -j 2 beside `yes > /dev/null`
//                    side_left 0.14 / 0.014 unverified 3/8 (the deadline cut it), side_right 0.44 / 0.018 ok 7/7;
//                    corner_left 0.30 / 0.008 ok 4/7, corner_right 0.05 / 0.002 ok 4/6, rear 0.17 / 0.003 ok 5/6
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "calibrate_chain.hpp"
#include "sanitizers.hpp"
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
    const std::string doubt = l.value("doubt", "");
    std::printf("%s %-13s %-11s error %.3f cm %.4f deg  frames %d/%d  registrations %zu  inliers %.2f  %.1f s%s%s\n",
                preset.c_str(), sensor.c_str(), l.value("verdict", "-").c_str(), c.errors[sensor].cm,
                c.errors[sensor].deg, e.value("frames_registered", 0), e.value("frames_selected", 0),
                l.value("registrations", nlohmann::json::array()).size(), e.value("inlier_ratio", 0.0),
                l.value("seconds", 0.0), doubt.empty() ? "" : "  doubt: ", doubt.c_str());
  }
  return c;
}

/// The test-name suffix of a preset parameter: Corners or Side.
std::string presetTestName(const ::testing::TestParamInfo<const char*>& p) {
  return std::string(p.param) == "yard-corners" ? "Corners" : "Side";
}

class CalibrateYard : public ::testing::TestWithParam<const char*> {};

// The default deadline shared by every calibration lidar, as a user runs `rigcal calibrate`: every calibration
// lidar within the goal, and a verdict that does not lie — ok → within the goal; otherwise unverified, saying what
// would confirm it (the --deadline when the deadline cut the plan, or more frames). The condition: under
// `ctest -j 2` beside a CPU-bound process (the plan then gets about a third of the machine: side_left 3 of 8
// frames). With --deadline 4 / 2.5 on a quiet machine every lidar stayed within the goal; at 1.5 (one frame each)
// side_left came to 1.08 cm, unverified: a load that leaves each lidar a sixth of a core is beyond this test.
TEST_P(CalibrateYard, UnderTheDefaultDeadlineEveryLidarWithinTheGoal) {
  if (!kWallClockAsserted) GTEST_SKIP() << "deadline-bound: Release only";
  TempDir dir;
  const Calibrated c = calibrate(GetParam(), {}, dir);
  ASSERT_FALSE(c.report.is_null());
  ASSERT_GE(c.report["lidars"].size(), 2u);
  bool all_ok = true;
  for (const auto& l : c.report["lidars"]) {
    const std::string sensor = l["sensor"].get<std::string>();
    ASSERT_TRUE(c.errors.count(sensor)) << sensor << " missing from compare's output";
    const LidarError e = c.errors.at(sensor);
    const std::string verdict = l.value("verdict", "");
    EXPECT_LT(e.cm, 1.0) << sensor << " (" << verdict << ")";
    EXPECT_LT(e.deg, 0.05) << sensor << " (" << verdict << ")";
    all_ok = all_ok && verdict == "ok";
    if (verdict == "ok") continue;
    EXPECT_EQ(verdict, "unverified") << sensor;
    // What would confirm it: a --deadline when the deadline cut the plan short of evidence; otherwise (every
    // frame registered, frames that scatter more than the goal) more frames.
    const bool more_time = l["evidence"].value("suggested_deadline_s", 0.0) > 0.0;
    const bool more_frames = l.value("doubt", "").find("more frames would narrow it") != std::string::npos;
    EXPECT_TRUE(more_time || more_frames) << sensor << ": say what would confirm it: " << l.value("doubt", "");
  }
  EXPECT_EQ(c.exit_code, all_ok ? 0 : 6) << "exit 6 (unverified) unless every lidar is ok";
}

INSTANTIATE_TEST_SUITE_P(Yard, CalibrateYard, ::testing::Values("yard-corners", "yard-side"),
                         presetTestName);

class CalibrateYardLong : public ::testing::TestWithParam<const char*> {};

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
                         presetTestName);

}  // namespace
}  // namespace rigcal::test
