// `rigcal sim --format both` recordings through the pipeline: the packet MCAP maps as the pcap, the
// PointCloud2 MCAP follows the same path; the parking-lot preset calibrates from either as from the pcap.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include "bag_pipeline_support.hpp"
#include "run_command.hpp"
#include "sanitizers.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;

/// `rigcal sim --format both` writes the recording as a pcap and as two MCAP bags (bagwrite's writer):
/// the packet MCAP maps as the pcap, row for row; the PointCloud2 MCAP (the simulated sweeps) follows the
/// same path within 5 mm.
TEST(BagSimMcap, MapFromTheSimulatorsMcapsFollowsThePcap) {
  TempDir dir;
  const auto sim = runRigcal({"sim", "--scenario", "parking-lot", "--duration", kSanitized ? "1.5" : "4", "--format",
                              "both", "--out", (dir / "sim").string()});
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const config::RigConfig rig = config::loadRigConfig(dir / "sim" / "rig.yaml");
  const auto map = [&](std::vector<std::string> input, const char* out) {
    std::vector<std::string> args{"map", "--config", (dir / "sim" / "rig.yaml").string(), "--out", (dir / out).string()};
    args.insert(args.end(), input.begin(), input.end());
    const auto r = runRigcal(args);
    EXPECT_EQ(r.exit_code, 0) << out << ": " << r.err;
    return trajectoryRows(dir / out);
  };
  const auto pcap = map({"--pcap", (dir / "sim" / "recording.pcap").string()}, "pcap");
  auto packets_args = simTopics(rig, "packets");
  packets_args.insert(packets_args.begin(), {"--bag", (dir / "sim" / "recording.mcap").string()});
  const auto packets = map(packets_args, "packets");
  auto points_args = simTopics(rig, "points");
  points_args.insert(points_args.begin(), {"--bag", (dir / "sim" / "recording_points.mcap").string()});
  const auto points = map(points_args, "points");
  ASSERT_GT(pcap.size(), kSanitized ? 3u : 25u);
  const std::size_t common = std::min(pcap.size(), packets.size());
  EXPECT_GE(common + kEndFrames, std::max(pcap.size(), packets.size()));
  for (std::size_t i = 0; i + kEndFrames < common; ++i) EXPECT_EQ(packets[i], pcap[i]) << "row " << i;
  // The simulator writes every sweep it cast; the pcap's decoder completes a few fewer (the first and last,
  // cut by the capture's ends): the PointCloud2 run may map a few more frames at the end.
  const std::size_t cloud_common = std::min(pcap.size(), points.size());
  EXPECT_GE(points.size() + kEndFrames, pcap.size());
  for (std::size_t i = 0; i + kEndFrames < cloud_common; ++i) {
    std::vector<std::string> a, b;
    std::istringstream sa(pcap[i]), sb(points[i]);
    for (std::string f; std::getline(sa, f, ',');) a.push_back(f);
    for (std::string f; std::getline(sb, f, ',');) b.push_back(f);
    ASSERT_GE(b.size(), 8u);
    EXPECT_EQ(a[1], b[1]) << "row " << i;
    for (std::size_t k = 5; k < 8; ++k) EXPECT_NEAR(std::stod(a[k]), std::stod(b[k]), 5e-3) << "row " << i;
  }
}

/// The whole parking-lot preset calibrated three ways: from its pcap, from its packet MCAP, and from its
/// PointCloud2 MCAP with `initial_extrinsics: from_bag` (its /tf_static holds rig.yaml's guesses); each
/// within the preset's bounds of the truth (1 cm, 0.05°, as calibrate_presets_test).
/// Measured (Release, 2 shared cores at load ~8, 380 s in all), errors from the 30 cm / 5° guesses:
///   pcap     front_left 0.342 cm 0.006°, front_right 0.429 cm 0.007°, base z 0.025 cm roll/pitch 0.032°
///   packets  front_left 0.343 cm 0.006°, front_right 0.393 cm 0.005°, base z 0.006 cm roll/pitch 0.037°
///   points   front_left 0.339 cm 0.008°, front_right 0.467 cm 0.009°, base z 0.013 cm roll/pitch 0.034°
/// On that busy machine the 10 s deadline let each run confirm only 1-4 of 10 frames: exit 6 (unverified),
/// alike for all three inputs; the comparison with the truth is the criterion here.
TEST(BagSimMcapLong, ParkingLotCalibratedFromItsMcapsAsFromItsPcap) {
  if (kSanitized || std::getenv("RIGCAL_LONG_TESTS") == nullptr) GTEST_SKIP() << "long test: RIGCAL_LONG_TESTS=1 (Release)";
  TempDir dir;
  const fs::path sim_dir = dir / "sim";
  const auto sim = runRigcal({"sim", "--scenario", "parking-lot", "--format", "both", "--out", sim_dir.string()});
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const config::RigConfig rig = config::loadRigConfig(sim_dir / "rig.yaml");
  std::ofstream(sim_dir / "rig_from_bag.yaml") << std::regex_replace(
      rigWithTopics(fileContents(sim_dir / "rig.yaml"), "points", "initial_extrinsics: from_bag\n"),
      std::regex("/sensing/lidar/(\\w+)/points"), "/$1/points");
  const auto calibrate = [&](const std::string& config, std::vector<std::string> input, const char* out) {
    std::vector<std::string> args{"calibrate", "--config", config, "--out", (dir / out).string()};
    args.insert(args.end(), input.begin(), input.end());
    const auto r = runRigcal(args);
    std::printf("%s:\n%s", out, r.out.c_str());
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 6) << out << ": " << r.err;
    const auto compared = runRigcal({"compare", "--truth", (sim_dir / "truth.yaml").string(), "--result",
                                     (dir / out / "calibration.yaml").string(), "--initial",
                                     (sim_dir / "rig.yaml").string(), "--max-cm", "1", "--max-deg", "0.05"});
    std::printf("%s", compared.out.c_str());
    EXPECT_EQ(compared.exit_code, 0) << out << ": " << compared.out << compared.err;
  };
  calibrate((sim_dir / "rig.yaml").string(), {"--pcap", (sim_dir / "recording.pcap").string()}, "pcap");
  auto packets = simTopics(rig, "packets");
  packets.insert(packets.begin(), {"--bag", (sim_dir / "recording.mcap").string()});
  calibrate((sim_dir / "rig.yaml").string(), packets, "packets");
  calibrate((sim_dir / "rig_from_bag.yaml").string(), {"--bag", (sim_dir / "recording_points.mcap").string()},
            "points");
}

}  // namespace
}  // namespace rigcal::test
