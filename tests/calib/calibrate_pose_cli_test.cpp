// `rigcal calibrate-pose` through the real binary: usage, input and data errors with their exit codes
// and one-line messages.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

#include <yaml-cpp/yaml.h>

#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/ply_io.hpp"
#include "rigcal/core/pose.hpp"
#include "run_command.hpp"
#include "sanitizers.hpp"
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

Pose poseOf(const YAML::Node& n) {
  return fromXyzRpy({n["x"].as<double>(), n["y"].as<double>(), n["z"].as<double>(), n["roll"].as<double>(),
                     n["pitch"].as<double>(), n["yaw"].as<double>()});
}

// The whole chain through the real binary: `rigcal sim` writes a VLP-16 capture in the wire format,
// the pose sensor's CSV (noisy, UTM-sized coordinates) and the truth; `rigcal calibrate-pose` decodes the
// capture as rig.yaml says and must recover truth.yaml's T_pose_lidar and time offset.
TEST(CalibratePoseCli, RecoversTheSimulatedPoseScenarioFromItsPcap) {
  TempDir sim, out;
  std::vector<std::string> sim_args{"sim", "--scenario", "pose", "--out", sim.path().string()};
  if (RIGCAL_SANITIZED) {  // instrumented binaries: 5 s of the drive, the exit codes and files only
    std::string text = fileContents(RIGCAL_POSE_SCENARIO);
    text = text.substr(0, text.find("  segments:")) +
           "  segments:\n    - {type: accelerate, to_kmh: 6, duration: 2.0}\n"
           "    - {type: turn, turn_deg: 60, duration: 3.0}\n";
    std::ofstream(sim / "short.yaml") << text;
    sim_args[2] = (sim / "short.yaml").string();
  }
  const auto simulated = runRigcal(sim_args);
  ASSERT_EQ(simulated.exit_code, 0) << simulated.err;
  ASSERT_TRUE(std::filesystem::exists(sim / "recording.pcap"));

  std::vector<std::string> args{"calibrate-pose", "--pcap", (sim / "recording.pcap").string(), "--poses",
                                (sim / "poses.csv").string(), "--config", (sim / "rig.yaml").string(),
                                "--sensor", "lidar", "--out", out.path().string()};
  if (RIGCAL_SANITIZED) args.insert(args.end(), {"--keep-ratio", "0.003", "--max-evals", "30"});
  const auto r = runRigcal(args);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  std::cout << r.out;
  EXPECT_NE(r.out.find("Motion over"), std::string::npos) << "the observability report is printed";
  EXPECT_NE(r.out.find("time offset to add to lidar timestamps"), std::string::npos);

  const YAML::Node truth = YAML::LoadFile((sim / "truth.yaml").string())["pose_sensor"]["lidars"]["lidar"];
  const Pose T_truth = poseOf(truth["T_pose_lidar"]);
  const double offset_truth = truth["time_offset_to_add_to_lidar_s"].as<double>();
  const YAML::Node got = YAML::LoadFile((out / "calibration.yaml").string())["pose_sensor"]["lidar"];
  const Pose T_got = poseOf(got);
  const double dt_cm = 100 * (T_got.translation() - T_truth.translation()).norm();
  const double dr_deg = rad2deg(rotationAngleBetween(T_got, T_truth));
  const double dtime_ms = 1e3 * std::abs(got["time_offset_s"].as<double>() - offset_truth);
  std::cout << "calibrate-pose vs truth: " << dt_cm << " cm, " << dr_deg << " deg, " << dtime_ms << " ms\n";

  const std::string text = fileContents(out / "calibration.txt");
  EXPECT_NE(text.find("Active Transformation Matrix from the Pose Sensor Frame to  the Lidar Frame:"),
            std::string::npos);
  EXPECT_NE(text.find("Time offset that must be added to lidar timestamps in seconds:"), std::string::npos);
  const PointTable cloud = readPly(out / "lidar_points.ply");
  EXPECT_GT(cloud.size(), RIGCAL_SANITIZED ? 100u : 40000u);
  for (const char* f : {"x", "y", "z", "intensity", "time"}) EXPECT_TRUE(cloud.has(f)) << f;
  if (RIGCAL_SANITIZED) return;
  EXPECT_LT(dt_cm, 2.0);
  EXPECT_LT(dr_deg, 0.1);
  EXPECT_LT(dtime_ms, 1.0);
}

}  // namespace
}  // namespace rigcal::test
