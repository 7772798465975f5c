// Every simulator preset calibrated from its MCAP bags as from its pcap: `rigcal sim --format both`, then
// `rigcal calibrate` (calibrate-pose for the pose preset) three ways: the pcap, the packet MCAP (the same
// payloads as VelodyneScan/PandarScan/... messages) and the PointCloud2 MCAP (the simulated sweeps) with
// `initial_extrinsics: from_bag` (its /tf_static holds rig.yaml's guesses). Each bag result must agree with
// the pcap result: every sensor's T_base_sensor within 1 cm and 0.1° (the calibrations run against a
// deadline, so runs differ a little even from one input); the comparison with truth.yaml is printed.
// Measured (Release, 2 cores shared at load 6-15; largest bag-vs-pcap difference over the preset's sensors,
// packet MCAP / PointCloud2 MCAP): street 0.76 cm 0.031° / 0.17 cm 0.008° (786 s); lost 0.40 cm 0.013° /
// 0.30 cm 0.012° (236 s); base-motion 0 / 0.011 cm 0.046° (397 s); yard-corners 0.006 cm 0.0002° / 0.45 cm
// 0.028° (453 s); pose 0 / 1.35 cm 0.022° 0.02 ms (81 s); yard-side mapping lidar 0 / 0.019 cm (244 s).
// The full presets are long (RIGCAL_LONG_TESTS=1, Release); the default suite runs the pose preset from
// its pcap and its packet MCAP with a lighter optimiser (~9 s CPU).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>

#include "bag_pipeline_support.hpp"
#include "rigcal/core/pose.hpp"
#include "run_command.hpp"
#include "sanitizers.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;

bool longTests() { return !kSanitized && std::getenv("RIGCAL_LONG_TESTS") != nullptr; }

constexpr double kAgreeCm = 1.0, kAgreeDeg = 0.1;

Pose poseOf(const YAML::Node& n) {
  return fromXyzRpy({n["x"].as<double>(), n["y"].as<double>(), n["z"].as<double>(), n["roll"].as<double>(),
                     n["pitch"].as<double>(), n["yaw"].as<double>()});
}

struct Difference {
  double cm = 0, deg = 0;
};

Difference between(const Pose& a, const Pose& b) {
  return {100 * (a.translation() - b.translation()).norm(), rad2deg(rotationAngleBetween(a, b))};
}

/// The simulated preset with both bags, and the rig file that takes its sources and guesses from the
/// PointCloud2 bag.
void simulateWithBags(const std::string& scenario, const fs::path& sim_dir, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{"sim", "--scenario", scenario, "--format", "both", "--out", sim_dir.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto sim = runRigcal(args);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  std::ofstream(sim_dir / "rig_from_bag.yaml") << std::regex_replace(
      rigWithTopics(fileContents(sim_dir / "rig.yaml"), "points", "initial_extrinsics: from_bag\n"),
      std::regex("/sensing/lidar/(\\w+)/points"), "/$1/points");
}

/// `rigcal calibrate` of a preset from the pcap and both MCAPs; every bag result against the pcap's. With
/// `mapping_only`, the calibration lidars' results are held only to an honest verdict (exit 0 only within
/// the goal), not to agreement: for a preset whose calibration lidars do not converge from the pcap either.
void calibrateThreeWays(const std::string& scenario, bool mapping_only = false) {
  TempDir dir;
  const fs::path sim_dir = dir / "sim";
  ASSERT_NO_FATAL_FAILURE(simulateWithBags(scenario, sim_dir));
  const config::RigConfig rig = config::loadRigConfig(sim_dir / "rig.yaml");
  const auto calibrate = [&](const fs::path& config, std::vector<std::string> input, const char* out) {
    std::vector<std::string> args{"calibrate", "--config", config.string(), "--out", (dir / out).string()};
    args.insert(args.end(), input.begin(), input.end());
    const auto r = runRigcal(args);
    // 6: results the deadline left unverified, alike for every input on a busy machine.
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 6) << scenario << " " << out << ": " << r.err;
    const auto compared = runRigcal({"compare", "--truth", (sim_dir / "truth.yaml").string(), "--result",
                                     (dir / out / "calibration.yaml").string(), "--initial",
                                     (sim_dir / "rig.yaml").string()});
    std::printf("%s from %s (exit %d), against the truth:\n%s", scenario.c_str(), out, r.exit_code,
                compared.out.c_str());
    if (mapping_only && r.exit_code == 0) {
      const auto goal = runRigcal({"compare", "--truth", (sim_dir / "truth.yaml").string(), "--result",
                                   (dir / out / "calibration.yaml").string(), "--max-cm", "1", "--max-deg", "0.05"});
      EXPECT_EQ(goal.exit_code, 0) << scenario << " " << out << ": called ok off the goal\n" << goal.out;
    }
    return YAML::LoadFile((dir / out / "calibration.yaml").string())["T_base_sensor"];
  };
  const YAML::Node pcap = calibrate(sim_dir / "rig.yaml", {"--pcap", (sim_dir / "recording.pcap").string()}, "pcap");
  auto packet_args = simTopics(rig, "packets");
  packet_args.insert(packet_args.begin(), {"--bag", (sim_dir / "recording.mcap").string()});
  const YAML::Node packets = calibrate(sim_dir / "rig.yaml", packet_args, "packets");
  const YAML::Node points =
      calibrate(sim_dir / "rig_from_bag.yaml", {"--bag", (sim_dir / "recording_points.mcap").string()}, "points");
  for (const auto& s : rig.sensors) {
    if (mapping_only && s.name != rig.roles.mapping_lidar) continue;
    ASSERT_TRUE(pcap[s.name]) << scenario << ": no " << s.name << " in the pcap's calibration.yaml";
    for (const auto& [form, result] : {std::pair{"packets", packets}, std::pair{"points", points}}) {
      ASSERT_TRUE(result[s.name]) << scenario << " " << form << ": no " << s.name;
      const Difference d = between(poseOf(result[s.name]), poseOf(pcap[s.name]));
      std::printf("%s %s %s vs pcap: %.3f cm %.4f deg\n", scenario.c_str(), form, s.name.c_str(), d.cm, d.deg);
      EXPECT_LT(d.cm, kAgreeCm) << scenario << " " << form << " " << s.name;
      EXPECT_LT(d.deg, kAgreeDeg) << scenario << " " << form << " " << s.name;
    }
  }
}

TEST(SimMcapPresetsLong, Street) {
  if (!longTests()) GTEST_SKIP() << "long test: RIGCAL_LONG_TESTS=1 (Release)";
  calibrateThreeWays("street");
}

TEST(SimMcapPresetsLong, Lost) {
  if (!longTests()) GTEST_SKIP() << "long test: RIGCAL_LONG_TESTS=1 (Release)";
  calibrateThreeWays("lost");
}

TEST(SimMcapPresetsLong, BaseMotion) {
  if (!longTests()) GTEST_SKIP() << "long test: RIGCAL_LONG_TESTS=1 (Release)";
  calibrateThreeWays("base-motion");
}

TEST(SimMcapPresetsLong, YardCorners) {
  if (!longTests()) GTEST_SKIP() << "long test: RIGCAL_LONG_TESTS=1 (Release)";
  calibrateThreeWays("yard-corners");
}

// The sideways lidars of yard-side are not calibrated reliably from any input (lidar_lidar_mounts_test:
// "not solved", held to an honest verdict). Measured at load 10-15: side_left 37.7 cm off the truth from
// the pcap, 53.3 cm from the packet MCAP, 36.4 cm from the PointCloud2 MCAP, all exit 6 (unverified);
// side_right 0.6-0.7 cm, 0.05-0.11°. The mapping lidar agrees (0.000 / 0.007 cm).
TEST(SimMcapPresetsLong, YardSide) {
  if (!longTests()) GTEST_SKIP() << "long test: RIGCAL_LONG_TESTS=1 (Release)";
  calibrateThreeWays("yard-side", /*mapping_only=*/true);
}

/// The pose preset through calibrate-pose from each input; the bags' poses come from their /odom.
struct PoseResult {
  Pose T;
  double offset_s = 0;
};

/// With `points_cm` > 0 the PointCloud2 MCAP too, within points_cm / points_deg / points_ms of the pcap.
void calibratePoseFromBags(const std::vector<std::string>& optimiser, double points_cm, double points_deg = 0,
                           double points_ms = 0) {
  TempDir dir;
  const fs::path sim_dir = dir / "sim";
  ASSERT_NO_FATAL_FAILURE(simulateWithBags("pose", sim_dir));
  const auto calibrate = [&](std::vector<std::string> input, const char* out) {
    std::vector<std::string> args{"calibrate-pose", "--config", (sim_dir / "rig.yaml").string(), "--sensor", "lidar",
                                  "--out", (dir / out).string()};
    args.insert(args.end(), input.begin(), input.end());
    args.insert(args.end(), optimiser.begin(), optimiser.end());
    const auto r = runRigcal(args);
    EXPECT_EQ(r.exit_code, 0) << out << ": " << r.out << r.err;
    const YAML::Node got = YAML::LoadFile((dir / out / "calibration.yaml").string())["pose_sensor"]["lidar"];
    return PoseResult{poseOf(got), got["time_offset_s"].as<double>()};
  };
  const YAML::Node truth_node = YAML::LoadFile((sim_dir / "truth.yaml").string())["pose_sensor"]["lidars"]["lidar"];
  const PoseResult truth{poseOf(truth_node["T_pose_lidar"]), truth_node["time_offset_to_add_to_lidar_s"].as<double>()};
  const PoseResult pcap =
      calibrate({"--pcap", (sim_dir / "recording.pcap").string(), "--poses", (sim_dir / "poses.csv").string()}, "pcap");
  const PoseResult packets = calibrate({"--bag", (sim_dir / "recording.mcap").string(), "--pose-topic", "/odom"}, "packets");
  std::vector<std::pair<const char*, PoseResult>> results{{"pcap", pcap}, {"packets", packets}};
  if (points_cm > 0)
    results.emplace_back("points", calibrate({"--bag", (sim_dir / "recording_points.mcap").string(), "--pose-topic",
                                              "/odom"}, "points"));
  for (const auto& [form, r] : results) {
    const Difference to_truth = between(r.T, truth.T), to_pcap = between(r.T, pcap.T);
    std::printf("pose %s: vs truth %.3f cm %.4f deg %.3f ms; vs pcap %.3f cm %.4f deg %.3f ms\n", form, to_truth.cm,
                to_truth.deg, 1e3 * std::abs(r.offset_s - truth.offset_s), to_pcap.cm, to_pcap.deg,
                1e3 * std::abs(r.offset_s - pcap.offset_s));
  }
  // The packet MCAP holds the pcap's payloads and /odom the CSV's poses as written: the same result.
  const Difference packets_d = between(packets.T, pcap.T);
  EXPECT_LT(packets_d.cm, 1e-4);
  EXPECT_LT(packets_d.deg, 1e-4);
  EXPECT_NEAR(packets.offset_s, pcap.offset_s, 1e-6);
  if (points_cm <= 0) return;
  // The PointCloud2 MCAP holds the simulated sweeps, not the decoded packets: close, not equal.
  const PoseResult& points = results.back().second;
  const Difference points_d = between(points.T, pcap.T);
  EXPECT_LT(points_d.cm, points_cm);
  EXPECT_LT(points_d.deg, points_deg);
  EXPECT_LT(1e3 * std::abs(points.offset_s - pcap.offset_s), points_ms);
}

// The pose sensor's z is the loosely constrained parameter (only wide tilts show it): the PointCloud2 sweeps
// moved it by 1.2 cm against the decoded packets with the default optimiser, by up to 2.5 cm with other
// keep ratios (measured on this preset), hence 3 cm here.
TEST(SimMcapPresetsLong, Pose) {
  if (!longTests()) GTEST_SKIP() << "long test: RIGCAL_LONG_TESTS=1 (Release)";
  calibratePoseFromBags({"--threads", "1"}, 3.0, kAgreeDeg, 0.5);
}

// In the default suite (~9 s CPU): the whole pose drive from the pcap and from the packet MCAP with half the
// optimiser's evaluations; the result must be the same to the digit. (A light optimiser's result itself
// is not reliable: 60 evaluations ended 33 cm off once, so it is not compared with the truth here.)
TEST(SimMcapPresets, PoseFromThePacketMcapEqualsThePcap) {
  if (kSanitized) GTEST_SKIP() << "simulation and calibration of a drive: Release only";
  calibratePoseFromBags({"--max-evals", "100", "--threads", "1"}, 0);
}

}  // namespace
}  // namespace rigcal::test
