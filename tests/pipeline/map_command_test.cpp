// `rigcal map` as a real process on a real capture (HDL-32E, ../shared/data): outputs, stats, errors.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "rigcal/core/pcd_io.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

std::filesystem::path writeRig(const TempDir& dir) {
  const auto rig = dir / "rig.yaml";
  std::ofstream(rig) << "rig: hdl32-test\n"
                        "sensors:\n"
                        "  - {name: top, model: HDL-32E, source: {port: 2368}}\n"
                        "roles: {mapping_lidar: top}\n"
                        "initial_extrinsics:\n"
                        "  top: {x: 0, y: 0, z: 2}\n";
  return rig;
}

TEST(MapCommand, MapsARealCaptureAndWritesItsOutputs) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  TempDir dir;
  const auto out = dir / "out";
  const auto r = runRigcal({"map", "--config", writeRig(dir).string(), "--pcap", pcap.string(), "--out", out.string(),
                            "--stats", (dir / "stats.json").string(), "--cores", "0,1"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  // The stats table at exit, then where the outputs went.
  EXPECT_NE(r.out.find("mapper"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dropped"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wrote trajectory.csv"), std::string::npos) << r.out;

  // One line per registered scan after the header (the capture holds 7 whole or partial sweeps).
  std::istringstream csv(fileContents(out / "trajectory.csv"));
  std::string line;
  int rows = 0;
  while (std::getline(csv, line))
    if (!line.empty() && line[0] != '#') ++rows;
  EXPECT_GE(rows, 5);
  const PointTable map = readPcd(out / "map.pcd");
  EXPECT_GT(map.size(), 10000u);
  EXPECT_TRUE(std::filesystem::exists(out / "selection.txt"));
  const std::string json = fileContents(dir / "stats.json");
  EXPECT_EQ(json.front(), '{');
  EXPECT_NE(json.find("\"name\": \"mapper\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"dropped\": 0"), std::string::npos) << json;  // offline: lossless
}

TEST(MapCommand, UsageAndConfigErrorsAreOneLine) {
  TempDir dir;
  const auto rig = writeRig(dir);
  const auto no_input = runRigcal({"map", "--config", rig.string()});
  EXPECT_EQ(no_input.exit_code, 2);
  EXPECT_NE(no_input.err.find("needs an input"), std::string::npos) << no_input.err;

  const auto bad_cores = runRigcal({"map", "--config", rig.string(), "--live", "--cores", "x"});
  EXPECT_EQ(bad_cores.exit_code, 2);
  EXPECT_NE(bad_cores.err.find("--cores"), std::string::npos) << bad_cores.err;

  std::ofstream(dir / "bad.yaml") << "rig: x\nsensors: []\n";
  const auto bad_config = runRigcal({"map", "--config", (dir / "bad.yaml").string(), "--live"});
  EXPECT_EQ(bad_config.exit_code, 3) << bad_config.err;
  EXPECT_EQ(std::count(bad_config.err.begin(), bad_config.err.end(), '\n'), 1) << bad_config.err;
}

}  // namespace
}  // namespace rigcal::test
