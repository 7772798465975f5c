// Point-set match of the RS-Helios-16P decoder against the reference decodes of a real capture
// (data README, robosense/: nebula's unmerged RoboSense branch, commit c60082d5, one PCD per sweep).
#include <gtest/gtest.h>

#include <cstdio>

#include "rigcal/core/pcd_io.hpp"
#include "rigcal/drivers/robosense/robosense_decoder.hpp"
#include "robosense_test_util.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

using robosense_test::Xyz;

constexpr const char* kReferences[] = {
    "robosense/helios16p.1691031766781547066.reference.pcd", "robosense/helios16p.1691031766880833506.reference.pcd",
    "robosense/helios16p.1691031766980937333.reference.pcd", "robosense/helios16p.1691031767081713313.reference.pcd"};
constexpr std::size_t kReferencePoints[] = {15258, 15795, 15786, 15708};

std::vector<Xyz> readReference(const std::filesystem::path& file) {
  const PointTable table = readPcd(file);
  const auto& x = table.column("x");
  const auto& y = table.column("y");
  const auto& z = table.column("z");
  std::vector<Xyz> out(table.size());
  for (std::size_t i = 0; i < table.size(); ++i) out[i] = {x[i], y[i], z[i]};  // same axes as ours
  return out;
}

TEST(RobosenseReference, HeliosSweepsMatchNebulaReference) {
  RIGCAL_REQUIRE_DATA(capture_path, "robosense/helios16p.pcap");
  DecoderConfig config;
  config.model = "RS-Helios-16P";
  config.min_range_m = 0.2f;  // the reference was made with a 0.2 m lower limit (its nearest point: 0.2025 m)
  config.max_range_m = 180.0f;
  RobosenseDecoder decoder(config);
  AssemblerStats stats;
  const auto scans = robosense_test::decodeScans(decoder, robosense_test::loadCapture(capture_path), &stats);
  EXPECT_EQ(decoder.stats().difop_packets, 1u);
  EXPECT_EQ(decoder.stats().dropped_without_difop, 0u);
  EXPECT_EQ(stats.malformed, 0u);
  EXPECT_EQ(stats.lost_packets, 0u);

  std::size_t previous = 0;
  for (int r = 0; r < 4; ++r) {
    RIGCAL_REQUIRE_DATA(reference_path, kReferences[r]);
    const auto reference = readReference(reference_path);
    ASSERT_EQ(reference.size(), kReferencePoints[r]);
    // The reference names the sweep by its ROS receive stamp: find it by overlap.
    std::size_t best = scans.size(), best_matched = 0;
    for (std::size_t s = 0; s < scans.size(); ++s) {
      const std::size_t m = robosense_test::countMatched(robosense_test::xyzOf(scans[s]), reference, 1e-2);
      if (m > best_matched) best_matched = m, best = s;
    }
    ASSERT_LT(best, scans.size());
    if (r > 0) {
      EXPECT_EQ(best, previous + 1) << "the references are consecutive sweeps";
    }
    previous = best;
    const auto decoded = robosense_test::xyzOf(scans[best]);
    const double ref_mm = double(robosense_test::countMatched(decoded, reference, 1e-3)) / double(reference.size());
    const double ref_cm = double(best_matched) / double(reference.size());
    const double ours_mm = double(robosense_test::countMatched(reference, decoded, 1e-3)) / double(decoded.size());
    const double ours_cm = double(robosense_test::countMatched(reference, decoded, 1e-2)) / double(decoded.size());
    std::printf("RS-Helios-16P sweep %zu of %zu: reference %zu points, decoded %zu; reference within 1 mm %.4f, "
                "1 cm %.4f; decoded within 1 mm %.4f, 1 cm %.4f\n",
                best, scans.size(), reference.size(), decoded.size(), ref_mm, ref_cm, ours_mm, ours_cm);
    ::testing::Test::RecordProperty("ref" + std::to_string(r) + "_within_1mm", std::to_string(ref_mm));
    ::testing::Test::RecordProperty("ref" + std::to_string(r) + "_within_1cm", std::to_string(ref_cm));
    // Measured: 99.05-99.09 % within 1 mm, 99.97-99.99 % within 1 cm. The rest are laser 3 (DIFOP
    // elevation 8.90°): for ~0.9 % of the reference's points x y z disagree with that same file's own
    // distance / azimuth / elevation fields by up to ~4 mm (their z fits 8.89°), while ours agree with them.
    EXPECT_GE(ref_cm, 0.999);
    EXPECT_GE(ours_cm, 0.999);
    EXPECT_GE(ref_mm, 0.985);
    EXPECT_GE(ours_mm, 0.985);
    EXPECT_EQ(decoded.size(), reference.size()) << "same sweep window as the reference (cut at 0 deg)";
    EXPECT_EQ(scans[best].missing_packets, 0u);
  }
}

}  // namespace
}  // namespace rigcal::drivers
