// `rigcal decode` (the real binary) on the Pandar40P, Pandar64, PandarQT64 and PandarXT32M captures:
// every packet decodes, and the sweep the nebula reference covers comes out with its point count.
#include <gtest/gtest.h>

#include "rigcal/core/pcd_io.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

struct Case {
  const char* model;
  const char* capture;
  const char* min_range;     // the reference's range filter (data README, hesai/)
  const char* reference_points;
  const char* lost;          // udp_sequence gaps of the recording itself
};

TEST(HesaiModelsCli, DecodeGivesTheReferenceSweep) {
  for (const Case& c : {Case{"Pandar40P", "pandar40p_dual.pcap", "0.3", "points 56762 ", "0 lost"},
                        Case{"Pandar64", "pandar64_dual.pcap", "0.3", "points 93591 ", "0 lost"},
                        Case{"PandarQT64", "pandarqt64_dual.pcap", "0.1", "points 34158 ", "0 lost"},
                        Case{"PandarXT32M", "xt32m_laststrongest.pcap", "0.5", "points 13574 ", "852 lost"}}) {
    RIGCAL_REQUIRE_DATA(pcap, std::string("hesai/") + c.capture);
    TempDir out;
    const auto r = runRigcal({"decode", pcap.string(), "--sensor", c.model, "--calibration",
                              (dataDir() / "hesai" / (std::string(c.model) + ".csv")).string(), "--min-range",
                              c.min_range, "--max-range", "300", "--out", out.path().string()});
    ASSERT_EQ(r.exit_code, 0) << c.model << ": " << r.err;
    EXPECT_NE(r.out.find("(0 malformed, 0 ignored, " + std::string(c.lost)), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(c.reference_points), std::string::npos) << c.model << ": " << r.out;
    EXPECT_GT(readPcd(out / "scan_000002.pcd").size(), 10'000u) << c.model;
  }
}

}  // namespace
}  // namespace rigcal::test
