#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>

#include "rigcal/config/rig_config.hpp"
#include "rigcal/sim/outputs.hpp"
#include "sim_test_util.hpp"
#include "test_data.hpp"

namespace rigcal::sim {
namespace {

using test::poseFrom;

using rigcal::test::TempDir;
using rigcal::test::fileContents;

namespace fs = std::filesystem;

void writeAll(const Simulation& sim, const fs::path& dir) {
  writeTruthYaml(sim, dir / "truth.yaml");
  writePosesCsv(sim, dir / "poses.csv");
  writeRigFiles(sim, dir);
}

TEST(Outputs, TruthIsConsistent) {
  const Simulation sim(loadScenario("street"));
  TempDir dir;
  writeTruthYaml(sim, dir / "truth.yaml");
  const YAML::Node t = YAML::LoadFile((dir / "truth.yaml").string());
  EXPECT_EQ(t["scenario"].as<std::string>(), "street");
  EXPECT_EQ(t["seed"].as<std::uint64_t>(), sim.scenario().seed);
  const Pose T_bm = poseFrom(t["sensors"]["top"]["T_base_sensor"]);
  for (const std::string c : {"rear", "front", "left"}) {
    const YAML::Node s = t["sensors"][c];
    const Pose T_bc = poseFrom(s["T_base_sensor"]);
    // The composition check: T_mapping_calib == inverse(T_base_mapping) · T_base_calib.
    const Pose T_mc = poseFrom(t["T_mapping_calib"][c]);
    EXPECT_LT((T_mc.matrix() - (T_bm.inverse() * T_bc).matrix()).norm(), 1e-8) << c;
    // The quaternion and the rpy describe the same rotation, and match the scenario.
    const YAML::Node p = t["T_mapping_calib"][c];
    const Eigen::Quaterniond q(p["qw"].as<double>(), p["qx"].as<double>(), p["qy"].as<double>(), p["qz"].as<double>());
    EXPECT_LT((q.toRotationMatrix() - T_mc.linear()).norm(), 1e-8) << c;
    const SensorSpec& spec = sim.scenario().sensors[sim.scenario().sensorIndex(c)];
    EXPECT_LT((T_bc.matrix() - spec.T_base_sensor.matrix()).norm(), 1e-8) << c;
    EXPECT_EQ(s["clock_offset_ns"].as<TimeNs>(), spec.clock_offset_ns);
    EXPECT_DOUBLE_EQ(s["scan_phase_deg"].as<double>(), spec.scan_phase_deg);
  }
  EXPECT_EQ(t["end_time_ns"].as<TimeNs>() - t["start_time_ns"].as<TimeNs>(), sim.trajectory().duration());
}

TEST(Outputs, PoseScenarioTruthGivesTheLidarAlignAnswer) {
  const Simulation sim(loadScenario("pose"));
  TempDir dir;
  writeTruthYaml(sim, dir / "truth.yaml");
  const YAML::Node t = YAML::LoadFile((dir / "truth.yaml").string());
  const YAML::Node l = t["pose_sensor"]["lidars"]["lidar"];
  EXPECT_DOUBLE_EQ(l["time_offset_to_add_to_lidar_s"].as<double>(), -0.015);
  const Pose T_pl = poseFrom(l["T_pose_lidar"]);
  const Pose expected = sim.scenario().pose_sensor->T_base_pose.inverse() * sim.scenario().sensors[0].T_base_sensor;
  EXPECT_LT((T_pl.matrix() - expected.matrix()).norm(), 1e-8);
}

TEST(Outputs, RigYamlLoadsAndIsPerturbedByExactlyTheConfiguredAmount) {
  for (const bool perturb_mapping : {true, false}) {
    Scenario sc = loadScenario("street");
    sc.perturbation = {0.3, 5.0, perturb_mapping};
    const Simulation sim(sc);
    TempDir dir;
    const auto files = writeRigFiles(sim, dir.path());
    EXPECT_EQ(files.size(), sc.sensors.size() + 1);
    const config::RigConfig rig = config::loadRigConfig(dir / "rig.yaml");  // throws on any mistake
    EXPECT_EQ(rig.sensors.size(), 4u);
    EXPECT_EQ(rig.roles.mapping_lidar, "top");
    EXPECT_EQ(rig.roles.calibration_lidars, (std::vector<std::string>{"rear", "front", "left"}));
    EXPECT_EQ(rig.sensor("front").metadata, (dir / "front.json").lexically_normal());
    EXPECT_EQ(rig.sensor("left").time_source, TimeSource::kHostReceive);
    const Pose& T_bm = sc.sensors[0].T_base_sensor;
    const Pose& T_bm0 = rig.initial_T_base_sensor.at("top");
    if (perturb_mapping) {
      EXPECT_NEAR((T_bm0.translation() - T_bm.translation()).norm(), 0.3, 1e-8);
      EXPECT_NEAR(rad2deg(rotationAngleBetween(T_bm0, T_bm)), 5.0, 1e-6);
    } else {
      EXPECT_LT((T_bm0.matrix() - T_bm.matrix()).norm(), 1e-8);
    }
    for (const std::string c : {"rear", "front", "left"}) {
      const Pose truth = T_bm.inverse() * sc.sensors[sc.sensorIndex(c)].T_base_sensor;
      const Pose initial = T_bm0.inverse() * rig.initial_T_base_sensor.at(c);
      EXPECT_NEAR((initial.translation() - truth.translation()).norm(), 0.3, 1e-8) << c;
      EXPECT_NEAR(rad2deg(rotationAngleBetween(initial, truth)), 5.0, 1e-6) << c;
    }
  }
}

TEST(Outputs, VendorFilesCarryTheSimulatedAngles) {
  const Simulation sim(loadScenario("street"));
  TempDir dir;
  writeRigFiles(sim, dir.path());
  const YAML::Node ouster = YAML::LoadFile((dir / "front.json").string());
  const LidarModel& os = lidarModel("OS1-64");
  for (std::size_t i = 0; i < os.beamCount(); ++i)
    EXPECT_DOUBLE_EQ(ouster["beam_intrinsics"]["beam_altitude_angles"][i].as<double>(), os.beams[i].elevation_deg);
  EXPECT_EQ(ouster["lidar_data_format"]["udp_profile_lidar"].as<std::string>(), "RNG19_RFL8_SIG16_NIR16");
  EXPECT_EQ(ouster["config_params"]["udp_port_lidar"].as<int>(), 7502);
  const YAML::Node vel = YAML::LoadFile((dir / "top.calibration.yaml").string());
  const LidarModel& vls = lidarModel("VLS-128");
  ASSERT_EQ(vel["lasers"].size(), 128u);
  for (std::size_t i = 0; i < 128; ++i) {
    EXPECT_NEAR(vel["lasers"][i]["vert_correction"].as<double>(), deg2rad(vls.beams[i].elevation_deg), 1e-15);
    EXPECT_NEAR(vel["lasers"][i]["rot_correction"].as<double>(), -deg2rad(vls.beams[i].azimuth_offset_deg), 1e-15);
  }
  std::ifstream csv(dir / "left.angles.csv");
  std::string line;
  int lines = 0;
  while (std::getline(csv, line)) ++lines;
  EXPECT_EQ(lines, 33);
}

TEST(Outputs, PosesCsvIsTheLidarAlignLayout) {
  const Simulation sim(loadScenario("pose"));
  TempDir dir;
  writePosesCsv(sim, dir / "poses.csv");
  std::ifstream in(dir / "poses.csv");
  std::string line;
  std::vector<std::vector<double>> rows;
  std::vector<TimeNs> stamps;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    long long t = 0, k = 0;
    double v[7];
    ASSERT_EQ(std::sscanf(line.c_str(), "%lld, %lld, %lf, %lf, %lf, %lf, %lf, %lf, %lf", &t, &k, &v[0], &v[1], &v[2],
                          &v[3], &v[4], &v[5], &v[6]), 9)
        << line;
    ASSERT_EQ(k, long(rows.size()));
    stamps.push_back(t);
    rows.push_back(std::vector<double>(v, v + 7));
  }
  EXPECT_EQ(rows.size(), std::size_t(toSeconds(sim.trajectory().duration()) * 100) + 1);
  for (std::size_t i = 1; i < stamps.size(); ++i) ASSERT_EQ(stamps[i] - stamps[i - 1], 10 * kNsPerMs);
  EXPECT_EQ(stamps.front(), sim.startTime());
  const PoseSensorSpec& ps = *sim.scenario().pose_sensor;
  for (std::size_t i = 0; i < rows.size(); i += 37) {
    const auto& r = rows[i];
    EXPECT_NEAR(std::sqrt(r[3] * r[3] + r[4] * r[4] + r[5] * r[5] + r[6] * r[6]), 1.0, 1e-8);
    // UTM-like origin added; noise of a few millimetres around the truth.
    const Pose truth = sim.T_world_base(stamps[i]) * ps.T_base_pose;
    const Eigen::Vector3d p(r[0], r[1], r[2]);
    EXPECT_LT((p - ps.origin - truth.translation()).norm(), 6 * ps.position_noise_m + 1e-6);
    const Eigen::Quaterniond q(r[3], r[4], r[5], r[6]);
    EXPECT_LT(rad2deg(Eigen::AngleAxisd(q.toRotationMatrix().transpose() * truth.linear()).angle()),
              8 * ps.rotation_noise_deg);
  }
}

TEST(Outputs, SameSeedGivesByteIdenticalFilesAndAnotherSeedAnotherWorld) {
  TempDir a, b, c;
  writeAll(Simulation(loadScenario("parking-lot")), a.path());
  writeAll(Simulation(loadScenario("parking-lot")), b.path());
  std::size_t compared = 0;
  for (const auto& e : fs::directory_iterator(a.path())) {
    EXPECT_EQ(fileContents(e.path()), fileContents(b / e.path().filename().string())) << e.path().filename();
    ++compared;
  }
  EXPECT_EQ(compared, 6u);  // truth, poses, rig, and three sensor files
  Scenario other = loadScenario("parking-lot");
  other.seed = 99;
  const Simulation s1(loadScenario("parking-lot")), s2(other);
  writeAll(s2, c.path());
  EXPECT_NE(fileContents(a / "truth.yaml"), fileContents(c / "truth.yaml"));
  EXPECT_NE(fileContents(a / "rig.yaml"), fileContents(c / "rig.yaml"));
  // A different world: the scene's primitives are not where they were.
  const auto& b1 = s1.scene().content().boxes;
  const auto& b2 = s2.scene().content().boxes;
  std::size_t same = 0;
  for (std::size_t i = 0; i < std::min(b1.size(), b2.size()); ++i) same += b1[i].cx == b2[i].cx && b1[i].cy == b2[i].cy;
  EXPECT_LT(same, std::min(b1.size(), b2.size()) / 10);
  EXPECT_NE(s1.scene().ground().height(10, 10), s2.scene().ground().height(10, 10));
}

}  // namespace
}  // namespace rigcal::sim
