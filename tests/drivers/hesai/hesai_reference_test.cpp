// Point-set match against nebula's reference decodes of real captures (data README, hesai/).
#include <gtest/gtest.h>

#include "hesai_test_util.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

using hesai_test::Xyz;

struct ReferenceCase {
  const char* model;
  const char* capture;
  const char* calibration;
  const char* reference;
  float min_range_m;       // the range filter the reference was made with
  std::size_t expected_points;
  std::uint64_t missing_packets = 0;  // udp_sequence gaps the recording itself has inside the sweep
};

// The reference clouds are in Hesai's native axes (x right, y forward): ours are x = y_h, y = −x_h.
std::vector<Xyz> referenceInOurAxes(const std::filesystem::path& file) {
  const PointTable table = readPcd(file);
  const auto& x = table.column("x");
  const auto& y = table.column("y");
  const auto& z = table.column("z");
  std::vector<Xyz> out(table.size());
  for (std::size_t i = 0; i < table.size(); ++i) out[i] = {y[i], -x[i], z[i]};
  return out;
}

void checkReference(const ReferenceCase& c) {
  RIGCAL_REQUIRE_DATA(capture_path, std::string("hesai/") + c.capture);
  RIGCAL_REQUIRE_DATA(calibration_path, std::string("hesai/") + c.calibration);
  RIGCAL_REQUIRE_DATA(reference_path, std::string("hesai/") + c.reference);
  DecoderConfig config;
  config.model = c.model;
  config.calibration = calibration_path;
  config.min_range_m = c.min_range_m;
  config.max_range_m = 300.0f;
  auto decoder = makeHesaiDecoder(config);
  const auto capture = hesai_test::loadCapture(capture_path);
  const auto scans = hesai_test::decodeScans(*decoder, capture);
  const auto reference = referenceInOurAxes(reference_path);
  ASSERT_EQ(reference.size(), c.expected_points);

  // The reference is one full sweep: find the one it matches best, then demand a match both ways.
  std::size_t best = scans.size();
  std::size_t best_matched = 0;
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const std::size_t m = hesai_test::countMatched(hesai_test::xyzOf(scans[s]), reference, 1e-3);
    if (m > best_matched) best_matched = m, best = s;
  }
  ASSERT_LT(best, scans.size());
  const auto decoded = hesai_test::xyzOf(scans[best]);
  const std::size_t back = hesai_test::countMatched(reference, decoded, 1e-3);
  const double ref_to_ours = double(best_matched) / double(reference.size());
  const double ours_to_ref = double(back) / double(decoded.size());
  ::testing::Test::RecordProperty("scan", std::to_string(best));
  ::testing::Test::RecordProperty("reference_points", std::to_string(reference.size()));
  ::testing::Test::RecordProperty("decoded_points", std::to_string(decoded.size()));
  ::testing::Test::RecordProperty("reference_matched", std::to_string(best_matched));
  ::testing::Test::RecordProperty("decoded_matched", std::to_string(back));
  std::printf("%s: sweep %zu of %zu, reference %zu points (%zu matched), decoded %zu points (%zu matched)\n",
              c.model, best, scans.size(), reference.size(), best_matched, decoded.size(), back);
  EXPECT_GE(ref_to_ours, 0.999);
  EXPECT_GE(ours_to_ref, 0.999);
  EXPECT_EQ(decoded.size(), reference.size()) << "same sweep window as nebula (cut at 0 deg)";
  EXPECT_EQ(scans[best].missing_packets, c.missing_packets);
}

// XT references were made with the sensor's own 0.05 m lower limit (they hold points from 0.17 m).
TEST(HesaiReference, PandarXT32DualMatchesNebula) {
  checkReference({"PandarXT32", "xt32_dual.pcap", "PandarXT32.csv", "xt32_dual.reference.pcd", 0.05f, 63021});
}

TEST(HesaiReference, PandarXT16DualMatchesNebula) {
  checkReference({"PandarXT16", "xt16_dual.pcap", "PandarXT16.csv", "xt16_dual.reference.pcd", 0.05f, 26287});
}

TEST(HesaiReference, PandarQT128LastStrongestMatchesNebula) {
  checkReference({"PandarQT128", "qt128_laststrongest.pcap", "PandarQT128.csv",
                  "qt128_laststrongest.reference.pcd", 0.3f, 73560});
}

// The newer references were made with the sensors' own range limits (data README, hesai/).
TEST(HesaiReference, Pandar40PDualMatchesNebula) {
  checkReference({"Pandar40P", "pandar40p_dual.pcap", "Pandar40P.csv", "pandar40p_dual.reference.pcd", 0.3f, 56762});
}

TEST(HesaiReference, Pandar64DualMatchesNebula) {
  checkReference({"Pandar64", "pandar64_dual.pcap", "Pandar64.csv", "pandar64_dual.reference.pcd", 0.3f, 93591});
}

TEST(HesaiReference, PandarQT64DualMatchesNebula) {
  checkReference(
      {"PandarQT64", "pandarqt64_dual.pcap", "PandarQT64.csv", "pandarqt64_dual.reference.pcd", 0.1f, 34158});
}

// The XT32M recording lost packets: its udp_sequence jumps by 414, 45 and 396; the reference sweep
// holds the last jump (395 packets), so nebula's sweep and ours both lack those points.
TEST(HesaiReference, PandarXT32MLastStrongestMatchesNebula) {
  checkReference({"PandarXT32M", "xt32m_laststrongest.pcap", "PandarXT32M.csv",
                  "xt32m_laststrongest.reference.pcd", 0.5f, 13574, 395});
}

}  // namespace
}  // namespace rigcal::drivers
