// `rigcal calibrate --static` through the real binaries, as a user runs it: `rigcal sim` of a parked
// vehicle in a calibration bay (presets calibration-bay, calibration-bay-degenerate) → `rigcal calibrate
// --static` from its capture → `rigcal compare` against truth.yaml.
//  - the bay from the preset's guesses (0.3 m / 5° off): every lidar near the truth, ok;
//  - the bay from guesses 1 m / 60° off (the tilted side lidars), through the full-turn global stage;
//  - the degenerate bay (a flat floor and one wall): unverified, the free direction named, exit 6;
//  - the vehicle driving off during the capture: refused (exit 5) saying when and how much it moved;
//  - the vehicle rolling in first: the capture waits until it has stood for 0.5 s; never still: exit 5;
//  - the bay from its MCAP (`--bag`, `--topic`) as from its pcap;
//  - live: `calibrate --static --live` on loopback ports fed by `rigcal replay --rate 1 --clock now`.
// Bounds: see kMaxCm / kMaxDeg below (measured numbers there).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <thread>

#include <unistd.h>

#include "calibrate_chain.hpp"
#include "sanitizers.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

using Clock = std::chrono::steady_clock;

// The issue's bound. Measured (Release, machine shared at load 3-7), errors of T_mapping_calib with the
// shared-floor refinement: side_left 0.22 cm 0.007°, side_right 0.24 cm 0.007°, from the preset's guesses
// and from 1 m / 60° off alike (the ensemble alone: 0.97 cm 0.38° and 0.42 cm 0.30°); base z 0.04 cm,
// roll/pitch 0.005-0.012°.
constexpr double kMaxCm = 1.0;
constexpr double kMaxDeg = 0.05;

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "preset no longer has: " << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

CommandResult calibrateStatic(const std::filesystem::path& sim, const std::filesystem::path& out, double* seconds,
                              const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{"--static"};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto t0 = Clock::now();
  auto r = runRigcal(calibrateArgs(sim, out, args));
  *seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf("%s%s", r.out.c_str(), r.err.c_str());
  return r;
}

// The tilted right-hand lidar sees mostly floor and one wall: its weakest rotation holds just under 0.03 of
// the information, so the verdict may say so (unverified, exit 6, the direction named). Either way the
// result must be near the truth; an unverified one must say why.
void expectOkOrNamedDoubt(const CommandResult& r, const std::filesystem::path& out) {
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 6) << r.err;
  if (r.exit_code == 6) {
    // Honest reasons only: a weak direction, or a deadline too short for the loaded machine.
    EXPECT_TRUE(r.err.find("poorly constrained") != std::string::npos ||
                r.err.find("the deadline cut the plan") != std::string::npos)
        << r.err;
    EXPECT_EQ(readJson(out / "report.json")["status"], "unverified");
  } else {
    EXPECT_EQ(readJson(out / "report.json")["status"], "ok");
  }
}

void expectCloseToTruth(const std::filesystem::path& sim, const std::filesystem::path& out) {
  const auto compared = compareWithTruth(sim, out, kMaxCm, kMaxDeg);
  std::printf("%s\n", compared.out.c_str());
  EXPECT_EQ(compared.exit_code, 0) << compared.out << compared.err;
}

TEST(CalibrateStatic, BayFromGuessesOffByAFewDegrees) {
  if (kSanitized) GTEST_SKIP() << "seconds of registration in Release: minutes under sanitizers";
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(simulate("calibration-bay", dir / "sim"));
  double seconds = 0.0;
  const auto r = calibrateStatic(dir / "sim", dir / "out", &seconds);
  ASSERT_NO_FATAL_FAILURE(expectOkOrNamedDoubt(r, dir / "out"));
  expectCloseToTruth(dir / "sim", dir / "out");
  const auto report = readJson(dir / "out" / "report.json");
  EXPECT_EQ(report["input"]["mode"], "static");
  EXPECT_EQ(report["input"]["still"], "yes");
  ASSERT_TRUE(report.contains("base_lidar"));
  EXPECT_TRUE(report["base_lidar"]["ok"].get<bool>()) << report["base_lidar"].dump(2);
  for (const char* f : {"calibration.yaml", "map.pcd", "side_left_after.pcd", "side_right_before.pcd", "overview.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
  // One calibration_deadline_s for the whole calibration after the capture: the ensembles stop at 80 % of
  // it and leave the rest to the polish, information, floor refinement and base-lidar. What is not cut
  // (each pair's target build and global stage before its ensemble, the polish after it) grows with the
  // machine's load: measured 11.5-15.8 s of plan (4.7-5.0 CPU-s) at load 13-16 on the shared 2 cores. The
  // bound allows such a machine; it catches a plan that ignores the deadline (uncut: 18 CPU-s, 57 s there).
  if (kWallClockAsserted) {
    double plan = 0.0;
    for (const char* stage : {"stillness", "accumulate", "shared_floor_reference", "lidar_lidar", "base_lidar"})
      plan += report["stage_seconds"][stage].get<double>();
    EXPECT_LT(plan, 1.5 * report["deadline_s"].get<double>() + 3.0) << report["stage_seconds"];
  }
  std::printf("static calibration of 3 lidars: %.1f s wall, stages %s\n", seconds, report["stage_seconds"].dump().c_str());
}

TEST(CalibrateStatic, BayFromGuessesOneMetreAndSixtyDegreesOff) {
  if (kSanitized) GTEST_SKIP() << "seconds of registration in Release: minutes under sanitizers";
  TempDir dir;
  // The side lidars' guesses 1 m and 60° off the truth (the mapping lidar's stays true: the ground fixes it).
  std::string yaml = replaced(presetText("calibration-bay"), "translation_m: 0.3", "translation_m: 1.0");
  yaml = replaced(yaml, "rotation_deg: 5.0", "rotation_deg: 60.0");
  yaml = replaced(yaml, "mapping_lidar: true", "mapping_lidar: false");
  ASSERT_NO_FATAL_FAILURE(simulateYaml(yaml, dir / "sim"));
  double seconds = 0.0;
  // The full-turn global stage scores ~28000 poses per lidar: 20 s leave the ensemble its time on a busy box.
  const auto r = calibrateStatic(dir / "sim", dir / "out", &seconds, {"--deadline", "20"});
  ASSERT_NO_FATAL_FAILURE(expectOkOrNamedDoubt(r, dir / "out"));
  expectCloseToTruth(dir / "sim", dir / "out");
  const auto report = readJson(dir / "out" / "report.json");
  // The global stage's answer is unique: the second basin scores clearly worse.
  for (const char* lidar : {"side_left", "side_right"}) {
    const std::string key = std::string(lidar) + "_second_basin_ratio";
    ASSERT_TRUE(report["input"].contains(key)) << report["input"].dump(2);
    EXPECT_GT(std::stod(report["input"][key].get<std::string>()), 1.25) << key;
  }
}

TEST(CalibrateStatic, DegenerateBayIsReportedNotOk) {
  if (kSanitized) GTEST_SKIP() << "seconds of registration in Release: minutes under sanitizers";
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(simulate("calibration-bay-degenerate", dir / "sim"));
  double seconds = 0.0;
  const auto r = calibrateStatic(dir / "sim", dir / "out", &seconds);
  EXPECT_EQ(r.exit_code, 6) << r.err;
  EXPECT_NE(r.err.find("degenerate"), std::string::npos) << r.err;
  const auto report = readJson(dir / "out" / "report.json");
  EXPECT_EQ(report["status"], "unverified");
  // Nothing the lidars see fixes the translation along the wall (the wall runs along y).
  const std::string weak = report["input"]["front_weak_directions"].get<std::string>();
  EXPECT_NE(weak.find('y'), std::string::npos) << weak;
  EXPECT_NE(fileContents(dir / "out" / "calibration.yaml").find("unverified"), std::string::npos);
}

// Also under the sanitizers (the capture's driver threads and the stillness check; no registration runs).
TEST(CalibrateStatic, VehicleMovingDuringTheCaptureIsRefused) {
  TempDir dir;
  // Parked for 0.6 s, then it rolls away at walking pace within the 2 s capture.
  const std::string yaml = replaced(presetText("calibration-bay"), "    - {type: stop, duration: 3.0}",
                                    "    - {type: stop, duration: 0.6}\n    - {type: accelerate, to_kmh: 2, duration: 1.8}");
  ASSERT_NO_FATAL_FAILURE(simulateYaml(yaml, dir / "sim"));
  double seconds = 0.0;
  const auto r = calibrateStatic(dir / "sim", dir / "out", &seconds);
  EXPECT_EQ(r.exit_code, 5) << r.err;
  // When (seconds into the capture, which sweep) and how much (metres, degrees).
  EXPECT_TRUE(std::regex_search(r.err, std::regex(R"(moved during the static capture: [0-9.]+ s into it \(sweep [0-9]+\) the mapping lidar was [0-9.]+ m / [0-9.]+ deg)")))
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  const auto report = readJson(dir / "out" / "report.json");
  EXPECT_EQ(report["status"], "failed");
  EXPECT_EQ(report["input"]["still"], "no");
}

// The recording starts with the vehicle rolling into the bay (2.5 s at up to 4 km/h), then it stands for
// 3 s: the capture waits until the mapping sweeps agreed for 0.5 s, and the result is as from a parked
// start. --deadline 4: the shared-floor refinement lands on the same answer as with the default 10 s
// (measured 0.32 cm / 0.004° and 0.16 cm / 0.007° both ways), at 4 CPU-s instead of 10.
TEST(CalibrateStatic, CaptureWaitsUntilTheVehicleHasParked) {
  if (kSanitized) GTEST_SKIP() << "seconds of registration in Release: minutes under sanitizers";
  TempDir dir;
  const std::string yaml = replaced(presetText("calibration-bay"), "    - {type: stop, duration: 3.0}",
                                    "    - {type: accelerate, to_kmh: 4, duration: 1.5}\n"
                                    "    - {type: decelerate, to_kmh: 0, duration: 1.0}\n"
                                    "    - {type: stop, duration: 3.0}");
  ASSERT_NO_FATAL_FAILURE(simulateYaml(yaml, dir / "sim"));
  double seconds = 0.0;
  const auto r = calibrateStatic(dir / "sim", dir / "out", &seconds, {"--deadline", "4"});
  ASSERT_NO_FATAL_FAILURE(expectOkOrNamedDoubt(r, dir / "out"));
  const auto report = readJson(dir / "out" / "report.json");
  EXPECT_EQ(report["input"]["still"], "yes");
  EXPECT_EQ(report["input"]["capture_complete"], "yes");
  // Moving for the first 2.5 s (the last tenths at a crawl): no still half-second before ~2 s.
  const double waited = std::stod(report["input"]["waited_for_stillness_s"].get<std::string>());
  EXPECT_GT(waited, 2.0) << "opened while the vehicle still moved";
  EXPECT_LT(waited, 3.2) << "kept waiting after the vehicle stood";
  EXPECT_LT(std::stod(report["input"]["max_motion_m"].get<std::string>()), 0.03);
  expectCloseToTruth(dir / "sim", dir / "out");
}

// Also under the sanitizers (the driver threads waiting for the watch; no registration runs).
TEST(CalibrateStatic, VehicleNeverStillIsRefused) {
  TempDir dir;
  const std::string yaml = replaced(presetText("calibration-bay"), "    - {type: stop, duration: 3.0}",
                                    "    - {type: accelerate, to_kmh: 2, duration: 1.0}\n    - {type: cruise, duration: 2.0}");
  ASSERT_NO_FATAL_FAILURE(simulateYaml(yaml, dir / "sim"));
  double seconds = 0.0;
  const auto r = calibrateStatic(dir / "sim", dir / "out", &seconds);
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_TRUE(std::regex_search(r.err, std::regex(R"(never still for 0\.50 s: watched [0-9]+ mapping sweeps over [0-9.]+ s, the longest still stretch [0-9.]+ s)")))
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  const auto report = readJson(dir / "out" / "report.json");
  EXPECT_EQ(report["status"], "failed");
  EXPECT_EQ(report["input"]["still"], "no");
}

// The same parked bay from the simulator's packet MCAP (`rigcal sim --format both`; source.topic, --topic,
// initial_extrinsics: from_bag) as from its pcap: the same sweeps, so the same calibration (measured identical to the µm). --deadline 3:
// the shared-floor refinement settles both on the same minimum (about 3 CPU-s each).
TEST(CalibrateStatic, FromTheBaysMcapAsFromItsPcap) {
  if (kSanitized) GTEST_SKIP() << "seconds of registration in Release: minutes under sanitizers";
  TempDir dir;
  const auto sim = runRigcal({"sim", "--scenario", "calibration-bay", "--format", "both", "--out", (dir / "sim").string()});
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  double seconds = 0.0;
  const auto from_pcap = calibrateStatic(dir / "sim", dir / "pcap", &seconds, {"--deadline", "3"});
  ASSERT_NO_FATAL_FAILURE(expectOkOrNamedDoubt(from_pcap, dir / "pcap"));
  // The bag's own way of naming things: each lidar's source.topic and frame, the initial extrinsics from
  // its /tf_static (the simulator writes the rig's guesses there); --topic overrides one of them.
  std::string rig = fileContents(dir / "sim" / "rig.yaml");
  for (const char* lidar : {"top", "side_left", "side_right"})
    rig = std::regex_replace(rig, std::regex(std::string("(- name: ") + lidar + "\n    model: [^\n]+\n    source: \\{)"),
                             std::string("$1topic: /") + lidar + "/packets, frame: " + lidar + ", ");
  rig = std::regex_replace(rig, std::regex("initial_extrinsics:\n(  [^\n]*\n)+"), "initial_extrinsics: from_bag\n");
  ASSERT_NE(rig.find("initial_extrinsics: from_bag"), std::string::npos) << rig;
  ASSERT_NE(rig.find("topic: /side_right/packets, frame: side_right"), std::string::npos) << rig;
  std::ofstream(dir / "sim" / "from_bag.yaml") << rig;  // beside the vendor files it names
  const std::vector<std::string> args{"calibrate", "--static", "--config", (dir / "sim" / "from_bag.yaml").string(),
                                      "--bag", (dir / "sim" / "recording.mcap").string(), "--out", (dir / "bag").string(),
                                      "--deadline", "3", "--topic", "side_left=/side_left/packets"};
  const auto from_bag = runRigcal(args);
  std::printf("%s%s", from_bag.out.c_str(), from_bag.err.c_str());
  ASSERT_NO_FATAL_FAILURE(expectOkOrNamedDoubt(from_bag, dir / "bag"));
  const auto pcap_report = readJson(dir / "pcap" / "report.json");
  const auto bag_report = readJson(dir / "bag" / "report.json");
  EXPECT_EQ(bag_report["input"]["source"], (dir / "sim" / "recording.mcap").string());
  EXPECT_EQ(bag_report["input"]["mapping_sweeps"], pcap_report["input"]["mapping_sweeps"]);
  for (const char* lidar : {"top", "side_left", "side_right"}) {
    const auto& a = pcap_report["T_base_sensor"][lidar];
    const auto& b = bag_report["T_base_sensor"][lidar];
    for (const char* k : {"x", "y", "z"}) EXPECT_NEAR(a[k].get<double>(), b[k].get<double>(), 1e-3) << lidar << " " << k;
    for (const char* k : {"roll", "pitch", "yaw"})
      EXPECT_NEAR(a[k].get<double>(), b[k].get<double>(), 1e-4) << lidar << " " << k;  // rad: 0.006°
  }
  expectCloseToTruth(dir / "sim", dir / "bag");
}

// True once a UDP socket is bound to `port` (/proc/net/udp lists local ports in hex).
bool udpPortBound(int port) {
  std::ifstream in("/proc/net/udp");
  std::string text{std::istreambuf_iterator<char>(in), {}};
  char hex[8];
  std::snprintf(hex, sizeof hex, ":%04X ", unsigned(port));
  return text.find(hex) != std::string::npos;
}

TEST(CalibrateStatic, LiveFromSensorPortsOnLoopback) {
  if (kSanitized) GTEST_SKIP() << "real-time replay: a sanitized build cannot keep up";
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(simulate("calibration-bay", dir / "sim"));
  // Ports of this test's own (tests run in parallel); replay moves every destination port by the offset.
  const int offset = 20000 + int(::getpid() % 20000);
  std::string rig = fileContents(dir / "sim" / "rig.yaml");
  for (const int port : {7502, 2368, 2369})
    rig = std::regex_replace(rig, std::regex("port: " + std::to_string(port) + ","), "port: " + std::to_string(port + offset) + ",");
  std::ofstream(dir / "sim" / "live.yaml") << rig;  // beside the vendor files it names
  RigcalProcess calibrate({"calibrate", "--static", "--live", "--config", (dir / "sim" / "live.yaml").string(), "--out",
                           (dir / "out").string()});
  const auto until = Clock::now() + std::chrono::seconds(30);
  while (!(udpPortBound(7502 + offset) && udpPortBound(2368 + offset) && udpPortBound(2369 + offset)) &&
         Clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto replay = runRigcal({"replay", (dir / "sim" / "recording.pcap").string(), "--to", "127.0.0.1", "--rate", "1",
                                 "--clock", "now", "--config", (dir / "sim" / "rig.yaml").string(), "--port-offset",
                                 std::to_string(offset)});
  EXPECT_EQ(replay.exit_code, 0) << replay.err;
  // The capture ends by itself once every lidar covered static_capture_s (2 s of the 3 s recording); should
  // it not, Ctrl-C after a minute ends the input (and the assertions below say what was missing).
  std::atomic<bool> ended{false};
  std::thread watchdog([&] {
    for (int i = 0; i < 600 && !ended.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!ended.load()) calibrate.kill(SIGINT);
  });
  const CommandResult r = calibrate.wait();
  ended.store(true);
  watchdog.join();
  std::printf("%s%s", r.out.c_str(), r.err.c_str());
  ASSERT_NO_FATAL_FAILURE(expectOkOrNamedDoubt(r, dir / "out"));
  const auto report = readJson(dir / "out" / "report.json");
  EXPECT_EQ(report["input"]["source"], "live");
  EXPECT_EQ(report["input"]["capture_complete"], "yes");
  EXPECT_GE(std::stoi(report["input"]["mapping_sweeps"].get<std::string>()), 15);
  expectCloseToTruth(dir / "sim", dir / "out");
}

}  // namespace
}  // namespace rigcal::test
