#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>

#include "rigcal/config/rig_config.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/sim/simulation.hpp"
#include "test_data.hpp"

namespace rigcal::sim {
namespace {

using rigcal::test::TempDir;
using rigcal::test::rigcalBinary;

std::vector<std::string> modelsOf(const Scenario& s) {
  std::vector<std::string> m;
  for (const auto& x : s.sensors) m.push_back(x.model);
  return m;
}

TEST(Scenario, PresetsDescribeTheRequestedRigs) {
  const auto names = builtinScenarioNames();
  for (const char* preset : {"base-motion", "lost", "parking-lot", "pose", "street", "calibration-bay", "calibration-bay-degenerate",
                             "yard-corners", "yard-side"})
    EXPECT_NE(std::find(names.begin(), names.end(), preset), names.end()) << preset;
  const Scenario bay = loadScenario("calibration-bay");  // static calibration: parked, tilted side lidars
  EXPECT_EQ(modelsOf(bay), (std::vector<std::string>{"OS1-64", "VLP-16", "VLP-16"}));
  EXPECT_EQ(bay.calibration_lidars.size(), 2u);
  const Scenario p = loadScenario("parking-lot");
  EXPECT_EQ(modelsOf(p), (std::vector<std::string>{"OS1-64", "VLP-16", "VLP-16"}));
  EXPECT_EQ(p.calibration_lidars.size(), 2u);
  const Scenario s = loadScenario("street");
  EXPECT_EQ(modelsOf(s), (std::vector<std::string>{"VLS-128", "VLP-16", "OS1-64", "PandarXT32"}));
  const Scenario l = loadScenario("lost");
  EXPECT_FALSE(l.sensors[0].outages.empty());
  const Scenario q = loadScenario("pose");
  ASSERT_TRUE(q.pose_sensor);
  EXPECT_EQ(q.sensors.size(), 1u);
  EXPECT_EQ(q.sensors[0].clock_offset_ns - q.pose_sensor->clock_offset_ns, 15 * kNsPerMs);
  EXPECT_TRUE(q.trajectory.excitation.active());
  // Issue 19's unusual mounts: a 32-beam Velodyne maps; 16-beam corner lidars yawed ±45° and pitched down,
  // a rear one yawed 180°; side lidars with their spin axis horizontal, in a container yard.
  const Scenario yc = loadScenario("yard-corners");
  EXPECT_EQ(modelsOf(yc), (std::vector<std::string>{"VLP-32C", "VLP-16", "VLP-16", "VLP-16"}));
  EXPECT_EQ(yc.scene.layout, "container-yard");
  const Eigen::Vector3d rear_forward = yc.sensors[3].T_base_sensor.linear() * Eigen::Vector3d::UnitX();
  EXPECT_LT(rear_forward.x(), -0.9);  // looks backwards
  EXPECT_LT(rear_forward.z(), -0.15);  // and down (10-25°)
  const Scenario ys = loadScenario("yard-side");
  for (std::size_t i = 1; i < ys.sensors.size(); ++i) {
    const Eigen::Vector3d spin_axis = ys.sensors[i].T_base_sensor.linear() * Eigen::Vector3d::UnitZ();
    EXPECT_LT(std::abs(spin_axis.z()), 1e-6) << ys.sensors[i].name << ": spin axis horizontal";
  }
  // Sensors are not synchronised: distinct scan phases within each rig.
  for (const Scenario* sc : {&p, &s, &yc, &ys}) {
    std::set<double> phases;
    for (const auto& x : sc->sensors) phases.insert(x.scan_phase_deg);
    EXPECT_EQ(phases.size(), sc->sensors.size()) << sc->name;
  }
  for (const auto& name : builtinScenarioNames()) EXPECT_NO_THROW(Simulation{loadScenario(name)}) << name;
}

TEST(Scenario, MistakesAreReportedWithTheirPosition) {
  const auto error = [](const std::string& text) {
    try {
      parseScenario(text, "bad.yaml");
    } catch (const ScenarioError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string base = "scenario: x\nrig:\n  mapping_lidar: a\n  sensors:\n"
                           "    - {name: a, model: VLP-16, address: 1.2.3.4, port: 2368, extrinsic: {z: 2}}\n"
                           "scene: {layout: empty}\ntrajectory:\n  segments: [{type: stop, duration: 1}]\n";
  EXPECT_EQ(error(base), "no error");
  EXPECT_NE(error(base + "noize: {}\n").find("bad.yaml:9:1: unknown key 'noize'"), std::string::npos) << error(base + "noize: {}\n");
  std::string bad_model = base;
  bad_model.replace(bad_model.find("VLP-16"), 6, "VLP-17");
  EXPECT_NE(error(bad_model).find("bad.yaml:5:"), std::string::npos);
  EXPECT_NE(error(bad_model).find("known: VLP-16"), std::string::npos);
  std::string bad_ip = base;
  bad_ip.replace(bad_ip.find("1.2.3.4"), 7, "1.2.3.400");
  EXPECT_NE(error(bad_ip).find("not an IPv4 address"), std::string::npos);
  std::string bad_seg = base;
  bad_seg.replace(bad_seg.find("type: stop"), 10, "type: fly");
  EXPECT_NE(error(bad_seg).find("segment type 'fly'"), std::string::npos);
  EXPECT_THROW(loadScenario("no-such-preset"), ScenarioError);
}

TEST(Scenario, OusterUdpProfile) {
  const std::string base = "scenario: p\nrig:\n  mapping_lidar: a\n  sensors:\n"
                           "    - {name: a, model: MODEL, address: 10.0.0.2, port: 7502, extrinsic: {z: 2}, udp_profile: PROFILE}\n"
                           "scene: {layout: empty}\ntrajectory:\n  segments: [{type: stop, duration: 1}]\n";
  auto text = [&](const std::string& model, const std::string& profile) {
    std::string t = base;
    t.replace(t.find("MODEL"), 5, model);
    t.replace(t.find("PROFILE"), 7, profile);
    return t;
  };
  EXPECT_TRUE(parseScenario(text("OS1-64", "LEGACY"), "p").sensors[0].ouster_legacy);
  EXPECT_FALSE(parseScenario(text("OS1-128", "RNG19_RFL8_SIG16_NIR16"), "p").sensors[0].ouster_legacy);
  EXPECT_THROW(parseScenario(text("OS1-64", "RNG15"), "p"), ScenarioError);
  EXPECT_THROW(parseScenario(text("VLP-16", "LEGACY"), "p"), ScenarioError);
}

TEST(Scenario, LoadsAFileByPath) {
  TempDir dir;
  std::ofstream(dir / "mine.yaml") << "scenario: mine\nrig:\n  mapping_lidar: a\n  sensors:\n"
                                      "    - {name: a, model: PandarXT32, address: 10.0.0.2, port: 2368, extrinsic: {z: 2}}\n"
                                      "scene: {layout: street}\ntrajectory:\n  segments: [{type: stop, duration: 1}]\n";
  const Scenario s = loadScenario((dir / "mine.yaml").string());
  EXPECT_EQ(s.name, "mine");
  EXPECT_EQ(s.file, dir / "mine.yaml");
}

std::pair<int, std::string> runRigcal(const std::string& args) {
  const std::string cmd = rigcalBinary().string() + " " + args + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 512> buf{};
  while (pipe && std::fgets(buf.data(), int(buf.size()), pipe)) out += buf.data();
  const int status = pipe ? ::pclose(pipe) : -1;
  return {WEXITSTATUS(status), out};
}

TEST(SimCommand, WritesTruthPosesRigAndACaptureThatDecodeAndCheckConfigRead) {
  TempDir dir;
  // Two lidars of different vendors, a short drive: rig.yaml names each one's calibration/metadata
  // file, and `rigcal decode` / `rigcal check-config` work on the output folder as it is.
  std::ofstream(dir / "two.yaml") << "scenario: two\nseed: 5\nrig:\n  mapping_lidar: top\n  calibration_lidars: [side]\n"
                                     "  sensors:\n"
                                     "    - {name: top, model: OS1-64, address: 10.5.5.87, port: 7502, extrinsic: {z: 2}}\n"
                                     "    - {name: side, model: VLP-16, address: 10.0.0.2, port: 2368, extrinsic: {x: 1, z: 1.5}}\n"
                                     "scene: {layout: parking-lot}\ntrajectory:\n"
                                     "  start: {x: -20, y: -6, speed_kmh: 5}\n  segments: [{type: cruise, duration: 0.35}]\n";
  const std::filesystem::path out_dir = dir / "o";
  const auto [rc, out] = runRigcal("sim --scenario " + (dir / "two.yaml").string() + " --out " + out_dir.string());
  ASSERT_EQ(rc, 0) << out;
  for (const char* f : {"truth.yaml", "poses.csv", "rig.yaml", "top.json", "side.calibration.yaml", "recording.pcap"})
    EXPECT_TRUE(std::filesystem::exists(out_dir / f)) << f;
  EXPECT_NE(out.find("datagrams"), std::string::npos) << out;
  EXPECT_NO_THROW(config::loadRigConfig(out_dir / "rig.yaml"));
  const auto [check_rc, check_out] = runRigcal("check-config " + (out_dir / "rig.yaml").string());
  EXPECT_EQ(check_rc, 0) << check_out;
  const auto [dec_rc, dec_out] =
      runRigcal("decode " + (out_dir / "recording.pcap").string() + " --sensor OS1-64 --metadata " +
                (out_dir / "top.json").string() + " --port 7502 --format csv --out " + (dir / "top").string());
  EXPECT_EQ(dec_rc, 0) << dec_out;
  const auto [dec2_rc, dec2_out] =
      runRigcal("decode " + (out_dir / "recording.pcap").string() + " --sensor VLP-16 --calibration " +
                (out_dir / "side.calibration.yaml").string() + " --port 2368 --format csv --out " + (dir / "side").string());
  EXPECT_EQ(dec2_rc, 0) << dec2_out;
  for (const char* sensor : {"top", "side"}) {
    std::size_t files = 0;
    if (std::filesystem::exists(dir / sensor))
      for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir / sensor)) ++files;
    EXPECT_GE(files, 3u) << sensor << ": one file per sweep";
  }
  EXPECT_NE(runRigcal("sim --scenario nope --out " + dir.path().string()).first, 0);
}

TEST(SimCommand, DumpsSweepsAsPcd) {
  TempDir dir;
  std::ofstream(dir / "short.yaml") << "scenario: short\nrig:\n  mapping_lidar: a\n  sensors:\n"
                                       "    - {name: a, model: VLP-16, address: 10.0.0.2, port: 2368, extrinsic: {z: 2}}\n"
                                       "scene: {layout: parking-lot}\ntrajectory:\n"
                                       "  start: {x: -20, y: -6, speed_kmh: 5}\n  segments: [{type: cruise, duration: 0.35}]\n";
  const auto [rc, out] = runRigcal("sim --scenario " + (dir / "short.yaml").string() + " --out " + (dir / "o").string() +
                                   " --dump-scans --threads 1");
  ASSERT_EQ(rc, 0) << out;
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "o" / "scans" / "a")) {
    const PointTable t = readPcd(e.path());
    EXPECT_GT(t.size(), 0u);
    EXPECT_TRUE(t.has("offset_ns"));
    ++n;
  }
  EXPECT_GE(n, 3u);
}

}  // namespace
}  // namespace rigcal::sim
