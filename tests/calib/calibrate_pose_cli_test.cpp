// `rigcal calibrate-pose` through the real binary: usage, input and data errors with their exit codes
// and one-line messages.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

constexpr const char* kPosesHeader = "# timestamp_ns, index, px, py, pz, qw, qx, qy, qz\n";

std::string oneLine(const std::string& s) {
  EXPECT_EQ(std::count(s.begin(), s.end(), '\n'), 1) << s;
  return s;
}

TEST(CalibratePoseCli, UsageErrorsExitWith2) {
  TempDir dir;
  std::ofstream(dir / "x.pcap") << "x";
  std::ofstream(dir / "p.csv") << kPosesHeader;
  const std::string pcap = (dir / "x.pcap").string(), poses = (dir / "p.csv").string();
  EXPECT_EQ(runRigcal({"calibrate-pose", "--help"}).exit_code, 0);
  const auto neither = runRigcal({"calibrate-pose", "--pcap", pcap, "--poses", poses});
  EXPECT_EQ(neither.exit_code, 2);
  EXPECT_NE(neither.err.find("either --config with --sensor, or --model"), std::string::npos) << neither.err;
  EXPECT_EQ(runRigcal({"calibrate-pose", "--pcap", pcap, "--poses", poses, "--model", "VLP-16", "--config",
                       poses, "--sensor", "a"})
                .exit_code,
            2);
  EXPECT_EQ(runRigcal({"calibrate-pose", "--poses", poses, "--model", "VLP-16"}).exit_code, 2);
  const auto initial = runRigcal({"calibrate-pose", "--pcap", pcap, "--poses", poses, "--model", "VLP-16",
                                  "--initial", "1", "2", "3"});
  EXPECT_EQ(initial.exit_code, 2) << initial.err;
}

TEST(CalibratePoseCli, MissingFilesAreInputErrorsNamingTheFile) {
  TempDir dir;
  std::ofstream(dir / "p.csv") << kPosesHeader << "1000,0,0,0,0,1,0,0,0\n2000,1,0,0,0,1,0,0,0\n";
  const auto no_pcap = runRigcal({"calibrate-pose", "--pcap", (dir / "none.pcap").string(), "--poses",
                                  (dir / "p.csv").string(), "--model", "VLP-16"});
  EXPECT_EQ(no_pcap.exit_code, 4);
  EXPECT_NE(oneLine(no_pcap.err).find("none.pcap: capture not found"), std::string::npos) << no_pcap.err;
  std::ofstream(dir / "x.pcap") << "x";
  const auto no_poses = runRigcal({"calibrate-pose", "--pcap", (dir / "x.pcap").string(), "--poses",
                                   (dir / "none.csv").string(), "--model", "VLP-16"});
  EXPECT_EQ(no_poses.exit_code, 4);
  EXPECT_NE(oneLine(no_poses.err).find("none.csv: pose file not found"), std::string::npos) << no_poses.err;
  const auto bad_capture = runRigcal({"calibrate-pose", "--pcap", (dir / "x.pcap").string(), "--poses",
                                      (dir / "p.csv").string(), "--model", "VLP-16"});
  EXPECT_EQ(bad_capture.exit_code, 4);
  EXPECT_NE(oneLine(bad_capture.err).find("x.pcap"), std::string::npos) << bad_capture.err;
}

TEST(CalibratePoseCli, AMalformedPoseLineIsReportedWithItsNumber) {
  TempDir dir;
  std::ofstream(dir / "x.pcap") << "x";
  std::ofstream(dir / "poses.csv") << kPosesHeader << "1000,0,0,0,0,1,0,0,0\n"
                                   << "2000,1,0,0,0,1,0,0\n";  // line 3: a quaternion component missing
  const auto r = runRigcal({"calibrate-pose", "--pcap", (dir / "x.pcap").string(), "--poses",
                            (dir / "poses.csv").string(), "--model", "VLP-16"});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(oneLine(r.err).find("poses.csv:3:"), std::string::npos) << r.err;
}

TEST(CalibratePoseCli, ConfigErrorsExitWith3) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/vlp16_20hz_veloview.pcap");
  TempDir dir;
  std::ofstream(dir / "p.csv") << kPosesHeader << "1000,0,0,0,0,1,0,0,0\n2000,1,0,0,0,1,0,0,0\n";
  const auto r = runRigcal({"calibrate-pose", "--pcap", pcap.string(), "--poses", (dir / "p.csv").string(),
                            "--config", std::string(RIGCAL_RIGS_DIR) + "/velodyne-car.yaml", "--sensor",
                            "no_such_lidar"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(oneLine(r.err).find("no sensor named 'no_such_lidar'"), std::string::npos) << r.err;
}

TEST(CalibratePoseCli, PosesNotCoveringTheLidarTimeRangeNameBothRanges) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/vlp16_20hz_veloview.pcap");
  TempDir dir;
  {
    std::ofstream p(dir / "poses.csv");
    p << kPosesHeader;
    for (int i = 0; i <= 100; ++i) p << 1000000000LL + i * 10000000LL << ',' << i << ",0,0,0,1,0,0,0\n";
  }
  const auto r = runRigcal({"calibrate-pose", "--pcap", pcap.string(), "--poses", (dir / "poses.csv").string(),
                            "--model", "VLP-16"});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(r.out.find("lidar: 52 scans"), std::string::npos) << r.out;
  const std::string err = oneLine(r.err);
  EXPECT_NE(err.find("the poses do not cover the lidar time range: poses span [1.000000000, 2.000000000] s"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("lidar points span ["), std::string::npos) << err;
}

}  // namespace
}  // namespace rigcal::test
