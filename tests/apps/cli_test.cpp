#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "rigcal/core/pcd_io.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

TEST(Cli, VersionHelpAndUsageErrors) {
  const auto version = runRigcal({"--version"});
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.out.find('.'), std::string::npos);
  const auto help = runRigcal({"--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("Exit codes"), std::string::npos);
  EXPECT_NE(help.out.find("decode"), std::string::npos);
  EXPECT_EQ(runRigcal({}).exit_code, 2);
  EXPECT_EQ(runRigcal({"no-such-command"}).exit_code, 2);
  EXPECT_EQ(runRigcal({"decode", "--help"}).exit_code, 0);
}

// `rigcal sim --list`: one preset a line, its name apart from its description whatever the name's length
// (calibration-bay-degenerate had run into its text), and `sim --help` points there.
TEST(Cli, SimListsEveryPresetApartFromItsDescription) {
  const auto list = runRigcal({"sim", "--list"});
  ASSERT_EQ(list.exit_code, 0) << list.err;
  std::istringstream lines(list.out);
  std::vector<std::string> names;
  for (std::string line; std::getline(lines, line);) {
    const auto end = line.find(' ');
    ASSERT_NE(end, std::string::npos) << line;
    EXPECT_EQ(line.compare(end, 2, "  "), 0) << "name and description run together: " << line;
    names.push_back(line.substr(0, end));
  }
  for (const char* preset : {"parking-lot", "street", "yard-corners", "yard-side", "calibration-bay-degenerate"})
    EXPECT_NE(std::find(names.begin(), names.end(), preset), names.end()) << preset;
  EXPECT_NE(runRigcal({"sim", "--help"}).out.find("--list"), std::string::npos);
}

TEST(Cli, CheckConfigReportsConfigErrorsWithExitCode3) {
  const auto ok = runRigcal({"check-config", std::string(RIGCAL_RIGS_DIR) + "/velodyne-car.yaml"});
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_NE(ok.out.find("front_left"), std::string::npos);
  TempDir dir;
  std::ofstream(dir / "bad.yaml") << "rig: x\nsensors: []\n";
  const auto bad = runRigcal({"check-config", (dir / "bad.yaml").string()});
  EXPECT_EQ(bad.exit_code, 3);
  EXPECT_NE(bad.err.find("bad.yaml:2:"), std::string::npos) << bad.err;
}

TEST(Cli, DecodeWritesOneFilePerScanAndSummarises) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/OS-2-128-U1_v2.3.0_1024x10.pcap");
  const auto json = dataDir() / "ouster/OS-2-128-U1_v2.3.0_1024x10.json";
  TempDir out;
  const auto r = runRigcal({"decode", pcap.string(), "--sensor", "OS2-128", "--metadata", json.string(),
                            "--out", out.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("decoded 1 scans"), std::string::npos) << r.out;
  const PointTable t = readPcd(out / "scan_000000.pcd");
  EXPECT_GT(t.size(), 100000u);
  for (const char* f : {"x", "y", "z", "intensity", "ring", "offset_ns"}) EXPECT_TRUE(t.has(f)) << f;

  const auto csv = runRigcal({"decode", pcap.string(), "--sensor", "OS2-128", "--metadata", json.string(),
                              "--out", out.path().string(), "--format", "csv"});
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  std::ifstream in(out / "scan_000000.csv");
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "x,y,z,intensity,ring,offset_ns");
}

TEST(Cli, DecodeHandlesEveryVendor) {
  RIGCAL_REQUIRE_DATA(vlp16, "velodyne/vlp16_dual.pcap");
  TempDir out;
  const auto v = runRigcal({"decode", vlp16.string(), "--sensor", "VLP-16", "--out", (out / "v").string()});
  ASSERT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("decoded 5 scans"), std::string::npos) << v.out;  // 3 full turns + 2 partial ends
  const auto xt32 = dataDir() / "hesai/xt32_dual.pcap";
  const auto h = runRigcal({"decode", xt32.string(), "--sensor", "PandarXT32", "--calibration",
                            (dataDir() / "hesai/PandarXT32.csv").string(), "--out", (out / "h").string()});
  ASSERT_EQ(h.exit_code, 0) << h.err;
  EXPECT_NE(h.out.find("(0 malformed"), std::string::npos) << h.out;
  EXPECT_TRUE(std::filesystem::exists(out / "h" / "scan_000002.pcd"));
}

TEST(Cli, DecodeInputErrorsAreOneLineWithExitCode4) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/OS-2-128-U1_v2.3.0_1024x10.pcap");
  TempDir out;
  const auto unknown = runRigcal({"decode", pcap.string(), "--sensor", "VLP-99", "--out", out.path().string()});
  EXPECT_EQ(unknown.exit_code, 4);
  EXPECT_NE(unknown.err.find("unknown lidar model 'VLP-99'"), std::string::npos) << unknown.err;
  std::ofstream(out / "broken.json") << "{ not json";
  const auto bad_meta = runRigcal({"decode", pcap.string(), "--sensor", "Ouster", "--metadata",
                                   (out / "broken.json").string(), "--out", out.path().string()});
  EXPECT_EQ(bad_meta.exit_code, 4);
  EXPECT_NE(bad_meta.err.find("broken.json"), std::string::npos) << bad_meta.err;
  EXPECT_EQ(std::count(bad_meta.err.begin(), bad_meta.err.end(), '\n'), 1) << bad_meta.err;
}

TEST(Cli, DecodeOfACaptureWithoutThatSensorSaysSo) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/empty_pcap.pcap");
  const auto json = dataDir() / "ouster/OS-2-128-U1_v2.3.0_1024x10.json";
  TempDir out;
  const auto r = runRigcal({"decode", pcap.string(), "--sensor", "Ouster", "--metadata", json.string(),
                            "--out", out.path().string()});
  EXPECT_EQ(r.exit_code, 5);
  EXPECT_NE(r.err.find("no Ouster scans decoded"), std::string::npos) << r.err;
}

TEST(Cli, DecodeRobosenseWaitsForDifopAndSaysWhenNoneCame) {
  RIGCAL_REQUIRE_DATA(helios, "robosense/helios16p.pcap");
  TempDir out;
  // Both ports (MSOP 6699, DIFOP 7788): the data waits for the device-info packet, then decodes.
  const auto r = runRigcal({"decode", helios.string(), "--sensor", "RS-Helios-16P", "--min-range", "0.2", "--out",
                            (out / "r").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("decoded 6 scans from 751 packets (0 malformed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("scan_000001.pcd  points 15795"), std::string::npos) << r.out;
  // The data port alone: no angle calibration, no scan, and the reason.
  const auto d = runRigcal({"decode", helios.string(), "--sensor", "RS-Helios-16P", "--port", "6699", "--out",
                            (out / "d").string()});
  EXPECT_EQ(d.exit_code, 5);
  EXPECT_NE(d.err.find("no DIFOP packet"), std::string::npos) << d.err;
}

}  // namespace
}  // namespace rigcal::test
