// `rigcal calibrate` through the real binary: usage, config and input errors, and a real capture that
// holds no packets of the calibration lidar (not enough data: exit 5, the missing frames named, a
// partial report written).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <nlohmann/json.hpp>

#include "../apps/run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

std::filesystem::path writeRig(const TempDir& dir, const std::string& extra = "") {
  const auto path = dir / "rig.yaml";
  std::ofstream f(path);
  f << "rig: test-rig\n"
       "sensors:\n"
       "  - name: top\n"
       "    model: VLP-16\n"
       "    source: {port: 2368}\n"
       "  - name: left\n"
       "    model: VLP-16\n"
       "    source: {port: 2399}\n"
       "roles:\n"
       "  mapping_lidar: top\n"
       "  calibration_lidars: [left]\n"
       "initial_extrinsics:\n"
       "  top:  {x: 1.0, y: 0.0, z: 2.0, roll: 0.0, pitch: 0.0, yaw: 0.0}\n"
       "  left: {x: 2.0, y: 0.8, z: 1.0, roll: 0.0, pitch: 0.0, yaw: 0.7}\n"
       "parameters:\n"
       "  lidar_calibration_max_frames: 10\n"
    << extra;
  return path;
}

TEST(CalibrateCommand, NeitherPcapNorLiveIsAUsageError) {
  TempDir dir;
  const auto r = runRigcal({"calibrate", "--config", writeRig(dir).string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--pcap or --bag or --live or --shm is required"), std::string::npos) << r.err;
}

// The pipeline options of `rigcal map` work here too: --cores pins, --stats writes the stage latencies.
TEST(CalibrateCommand, StatsAndCoresLikeRigcalMap) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/vlp16_20hz_veloview.pcap");
  TempDir dir;
  const auto stats = dir / "stats.json";
  const auto r = runRigcal({"calibrate", "--config", writeRig(dir, "  min_mapping_pointcloud_size: 1000\n").string(),
                            "--pcap", pcap.string(), "--out", (dir / "out").string(), "--cores", "0", "--stats",
                            stats.string()});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;  // `left` sends nothing: not enough data, but mapped
  ASSERT_TRUE(std::filesystem::exists(stats)) << r.err;
  std::ifstream in(stats);
  const auto j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.contains("stages")) << j.dump(2);
  bool mapper = false;
  for (const auto& s : j["stages"])
    if (s["name"] == "mapper") mapper = s["processed"].get<int>() > 10;
  EXPECT_TRUE(mapper) << "the mapper's stats: " << j.dump(2);
  EXPECT_NE(r.out.find("mapper"), std::string::npos) << "the stats table on stdout: " << r.out;
  const auto bad = runRigcal({"calibrate", "--config", writeRig(dir).string(), "--pcap", pcap.string(), "--cores",
                              "0,x", "--out", (dir / "out2").string()});
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--cores"), std::string::npos) << bad.err;
  const auto both = runRigcal({"calibrate", "--config", writeRig(dir).string(), "--pcap", pcap.string(), "--shm"});
  EXPECT_EQ(both.exit_code, 2) << both.err;
}

// A missing --pcap is an input error naming the file (exit 4, as in every command).
TEST(CalibrateCommand, MissingPcapIsAnInputErrorNamingTheFile) {
  TempDir dir;
  const auto r = runRigcal({"calibrate", "--config", writeRig(dir).string(), "--pcap", (dir / "nope.pcap").string(),
                            "--out", (dir / "out").string()});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("nope.pcap: capture not found"), std::string::npos) << r.err;
}

TEST(CalibrateCommand, BadConfigIsAConfigErrorWithItsLocation) {
  TempDir dir;
  const auto rig = writeRig(dir, "  lidar_calibration_max_framez: 3\n");
  const auto r = runRigcal({"calibrate", "--config", rig.string(), "--pcap", rig.string()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("rig.yaml:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("lidar_calibration_max_frames"), std::string::npos) << r.err;
}

TEST(CalibrateCommand, NoCalibrationLidarPacketsIsNotEnoughDataWithAPartialReport) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/vlp16_dual.pcap");
  TempDir dir;
  const auto out = dir / "out";
  const auto r = runRigcal({"calibrate", "--config", writeRig(dir).string(), "--pcap", pcap.string(), "--out",
                            out.string(), "--deadline", "2"});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.err.find("left"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  ASSERT_TRUE(std::filesystem::exists(out / "report.json"));
  ASSERT_TRUE(std::filesystem::exists(out / "calibration.yaml"));
  std::ifstream in(out / "report.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_TRUE(j["input"].contains("left_missing")) << j.dump(2);
  EXPECT_EQ(j["input"]["left_scans"], "0");
  EXPECT_NE(r.out.find("parent -> child"), std::string::npos) << r.out;
  // The failure, not the initial guess under the normal header: no extrinsic a reader could take for a result.
  const std::string yaml = [&] {
    std::ifstream y(out / "calibration.yaml");
    return std::string((std::istreambuf_iterator<char>(y)), std::istreambuf_iterator<char>());
  }();
  EXPECT_NE(yaml.find("status: failed"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("left"), std::string::npos) << "the failure names the lidar: " << yaml;
  EXPECT_EQ(yaml.find("T_base_sensor"), std::string::npos) << yaml;
  EXPECT_EQ(j["status"], "failed");
  // Base-lidar calibration is off by default: the summary and the report say so.
  EXPECT_NE(r.out.find("calibrate_base_frame: false"), std::string::npos) << r.out;
  EXPECT_TRUE(j.contains("base_lidar_skipped")) << j.dump(2);
}

}  // namespace
}  // namespace rigcal::test
