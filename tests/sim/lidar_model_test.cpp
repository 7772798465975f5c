#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>

#include "rigcal/core/pose.hpp"
#include "rigcal/sim/firing_scheduler.hpp"
#include "rigcal/sim/lidar_model.hpp"
#include "test_data.hpp"

namespace rigcal::sim {
namespace {

TEST(LidarModel, BuiltInModelsAndTheirShape) {
  const std::vector<std::pair<std::string, std::size_t>> expected = {
      {"VLP-16", 16}, {"VLP-32C", 32}, {"VLS-128", 128}, {"OS1-64", 64}, {"OS1-128", 128}, {"PandarXT32", 32}};
  for (const auto& [name, beams] : expected) {
    const LidarModel& m = lidarModel(name);
    EXPECT_EQ(m.beamCount(), beams) << name;
    EXPECT_DOUBLE_EQ(m.rotation_hz, 10.0) << name;
    for (const auto& b : m.beams) EXPECT_LT(b.time_offset_ns, m.firingPeriodNs()) << name << ": fires within its sequence";
  }
  EXPECT_THROW(lidarModel("HDL-64"), std::invalid_argument);
  EXPECT_DOUBLE_EQ(lidarModel("VLP-16").firingPeriodNs(), 55296.0);
  EXPECT_NEAR(lidarModel("VLP-16").firingsPerRotation(), 1808.45, 0.01);  // 0.2° resolution
  EXPECT_DOUBLE_EQ(lidarModel("OS1-64").firingsPerRotation(), 1024.0);
  EXPECT_DOUBLE_EQ(lidarModel("PandarXT32").firingsPerRotation(), 2000.0);  // 0.18°
  EXPECT_EQ(lidarModel("VLS-128").beams[127].time_offset_ns, 2665 * 16);    // group 15 + the idle slot
  EXPECT_EQ(lidarModel("VLP-32C").beams[31].time_offset_ns, 2304 * 15);    // fired in pairs
  EXPECT_EQ(lidarModel("PandarXT32").beams[31].time_offset_ns, 368 + 1512 * 31);
  EXPECT_DOUBLE_EQ(lidarModel("VLS-128").distance_unit_m, 0.004);
  EXPECT_DOUBLE_EQ(lidarModel("OS1-128").distance_unit_m, 0.001);
}

TEST(LidarModel, VelodyneAnglesAreTheVendorCalibration) {
  for (const auto& [name, file] : std::vector<std::pair<std::string, std::string>>{
           {"VLP-16", "velodyne/VLP16.calibration.yaml"}, {"VLP-32C", "velodyne/VLP32.calibration.yaml"},
           {"VLS-128", "velodyne/VLS128.calibration.yaml"}}) {
    RIGCAL_REQUIRE_DATA(path, file);
    const YAML::Node lasers = YAML::LoadFile(path.string())["lasers"];
    const LidarModel& m = lidarModel(name);
    ASSERT_EQ(lasers.size(), m.beamCount());
    for (const auto& l : lasers) {
      const auto id = l["laser_id"].as<std::size_t>();
      EXPECT_NEAR(deg2rad(m.beams[id].elevation_deg), l["vert_correction"].as<double>(), 1e-12) << name << " " << id;
      EXPECT_NEAR(-deg2rad(m.beams[id].azimuth_offset_deg), l["rot_correction"].as<double>(), 1e-12) << name << " " << id;
    }
  }
}

TEST(LidarModel, HesaiAndOusterAnglesAreTheVendorTables) {
  {
    RIGCAL_REQUIRE_DATA(path, "hesai/PandarXT32.csv");
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    const LidarModel& m = lidarModel("PandarXT32");
    for (std::size_t i = 0; i < 32; ++i) {
      ASSERT_TRUE(std::getline(in, line));
      double ch = 0, el = 0, az = 0;
      ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &ch, &el, &az), 3);
      EXPECT_DOUBLE_EQ(m.beams[i].elevation_deg, el);
      EXPECT_DOUBLE_EQ(m.beams[i].azimuth_offset_deg, az);
    }
  }
  for (const auto& [name, file] : std::vector<std::pair<std::string, std::string>>{
           {"OS1-64", "ouster/metadata/2_1_2_os1-991913000010-64.json"},
           {"OS1-128", "ouster/metadata/2_5_0_os-992146000760-128.json"}}) {
    RIGCAL_REQUIRE_DATA(path, file);
    const YAML::Node bi = YAML::LoadFile(path.string())["beam_intrinsics"];
    const LidarModel& m = lidarModel(name);
    for (std::size_t i = 0; i < m.beamCount(); ++i) {
      EXPECT_DOUBLE_EQ(m.beams[i].elevation_deg, bi["beam_altitude_angles"][i].as<double>());
      EXPECT_DOUBLE_EQ(m.beams[i].azimuth_offset_deg, bi["beam_azimuth_angles"][i].as<double>());
    }
    EXPECT_DOUBLE_EQ(m.beam_origin_radius_m * 1000, bi["lidar_origin_to_beam_origin_mm"].as<double>());
  }
}

TEST(LidarModel, VelodynePointIsWhatTheDecoderComputes) {
  // Decoders: x = r·cosω·cos(α − rot), y = −r·cosω·sin(α − rot), z = r·sinω, α the (interpolated)
  // azimuth of the laser's own firing time.
  const LidarModel& m = lidarModel("VLP-32C");
  const double block_az = 123.45, r = 17.5;
  for (std::size_t i = 0; i < m.beamCount(); ++i) {
    const double alpha = block_az + 360.0 * 10.0 * double(m.beams[i].time_offset_ns) * 1e-9;
    const double w = deg2rad(m.beams[i].elevation_deg), rot = -deg2rad(m.beams[i].azimuth_offset_deg);
    const Eigen::Vector3d expected(r * std::cos(w) * std::cos(deg2rad(alpha) - rot),
                                   -r * std::cos(w) * std::sin(deg2rad(alpha) - rot), r * std::sin(w));
    EXPECT_LT((m.point(i, block_az, r) - expected).norm(), 1e-9) << i;
  }
}

TEST(LidarModel, Helios16pPointIsWhatTheDecoderComputes) {
  // RoboSense decoders: x = d·cosω·cos(α + δ) + Rx·cos α, y = −d·cosω·sin(α + δ) − Rx·sin α, z = d·sinω,
  // α the block azimuth plus the slot's share (slot time / 111.12 µs) of the block's step (10 Hz ·
  // 55.56 µs), δ the laser's DIFOP horizontal offset, Rx = 34.98 mm; d is measured from the lens.
  const LidarModel& m = lidarModel("RS-Helios-16P");
  const double block_az = 271.3, d = 23.4, rx = 0.03498;
  ASSERT_EQ(m.beamCount(), 32u);
  for (std::size_t i = 0; i < m.beamCount(); ++i) {
    const double step_deg = 360.0 * 10.0 * 55.56e-6;
    const double alpha = deg2rad(block_az + step_deg * double(m.beams[i].time_offset_ns) / 111'120.0);
    const double delta = deg2rad(detail::helios16pHorizontalOffsetDeg(m, i)), w = deg2rad(m.beams[i].elevation_deg);
    const Eigen::Vector3d expected(d * std::cos(w) * std::cos(alpha + delta) + rx * std::cos(alpha),
                                   -d * std::cos(w) * std::sin(alpha + delta) - rx * std::sin(alpha), d * std::sin(w));
    EXPECT_LT((m.point(i, block_az, d) - expected).norm(), 1e-9) << i;
  }
}

TEST(LidarModel, OusterPointIsTheSdkFormulaInTheSensorFrame) {
  // Ouster: θ_enc = 2π(1 − m/W), θ_az = −2π·beam_az/360, φ = 2π·beam_alt/360, n = beam origin;
  // lidar frame x = (r − n)cos(θ_enc + θ_az)cos φ + n cos θ_enc, ..., then lidar_to_sensor (−x, −y, z + 36.18 mm).
  const LidarModel& m = lidarModel("OS1-64");
  const double n = m.beam_origin_radius_m, r = 12.345;
  for (int col : {0, 1, 255, 512, 1000}) {
    const double rotor_az = 180.0 + 360.0 * col / 1024.0;
    for (std::size_t b = 0; b < m.beamCount(); b += 7) {
      const double enc = 2 * M_PI * (1 - col / 1024.0), az = -deg2rad(m.beams[b].azimuth_offset_deg);
      const double phi = deg2rad(m.beams[b].elevation_deg);
      const Eigen::Vector3d lidar((r - n) * std::cos(enc + az) * std::cos(phi) + n * std::cos(enc),
                                  (r - n) * std::sin(enc + az) * std::cos(phi) + n * std::sin(enc), (r - n) * std::sin(phi));
      const Eigen::Vector3d sensor(-lidar.x(), -lidar.y(), lidar.z() + 0.03618);
      EXPECT_LT((m.point(b, rotor_az, r) - sensor).norm(), 1e-9) << col << " " << b;
    }
  }
}

TEST(FiringScheduler, PhaseLockOffsetAndOusterColumns) {
  const TimeNs start = 1'700'000'000'000'000'000;
  const LidarModel& vlp = lidarModel("VLP-16");
  const FiringScheduler s(vlp, 117.0, 2 * kNsPerMs, start);
  EXPECT_NEAR(s.rotorAzimuthDeg(start + 5 * kNsPerSec), 117.0, 1e-9) << "phase at every whole second";
  EXPECT_NEAR(s.rotorAzimuthDeg(start + 5 * kNsPerSec + 25 * kNsPerMs), 117.0 + 90.0, 1e-9);
  std::vector<SimFiring> f;
  s.schedule(start, start + kNsPerSec, f);
  ASSERT_GT(f.size(), 18000u);
  EXPECT_NEAR(double(f.size()), 1e9 / 55296.0, 1.0);
  for (std::size_t i = 1; i < f.size(); ++i) {
    ASSERT_EQ(f[i].sequence, f[i - 1].sequence + 1);
    ASSERT_EQ(f[i].sensor_time_ns - f[i - 1].sensor_time_ns, 55296);
    ASSERT_EQ(f[i].sensor_time_ns - f[i].true_time_ns, 2 * kNsPerMs) << "sensor clock = true + offset";
    // The frame counter steps exactly where the rotor passes 0°.
    if (f[i].frame != f[i - 1].frame) {
      ASSERT_LT(f[i].rotor_azimuth_deg, f[i - 1].rotor_azimuth_deg);
    }
  }
  EXPECT_GE(f.front().true_time_ns, start);
  EXPECT_LT(f.back().true_time_ns, start + kNsPerSec);

  const LidarModel& os = lidarModel("OS1-64");
  const FiringScheduler o(os, 37.5, 0, start);
  std::vector<SimFiring> g;
  o.schedule(start, start + kNsPerSec / 2, g);
  EXPECT_EQ(g.size(), 5120u);
  for (const SimFiring& x : g) {
    const double expected = 180.0 + 360.0 * x.column / 1024.0;
    const double diff = std::remainder(x.rotor_azimuth_deg - expected, 360.0);
    ASSERT_NEAR(diff, 0.0, 1e-5) << "column " << x.column;
    if (x.column == 0) {
      EXPECT_EQ(x.frame, o.frameIndex(x.sensor_time_ns));
    }
  }
  for (std::size_t i = 1; i < g.size(); ++i) ASSERT_EQ(g[i].frame != g[i - 1].frame, g[i].column == 0);
}

}  // namespace
}  // namespace rigcal::sim
