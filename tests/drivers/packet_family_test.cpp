// drivers::recognizePacket on every vendor's real captures: each capture's packets are its own family or
// unknown, never another vendor's (a false "foreign" would drop good packets); Ouster packets, which carry
// no magic, are never claimed by anyone.
#include "rigcal/drivers/packet_family.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "rigcal/drivers/pcap_source.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

struct Capture {
  const char* file;
  const char* model;
};

void PrintTo(const Capture& c, std::ostream* os) { *os << c.file; }

class PacketFamilyOfCapture : public ::testing::TestWithParam<Capture> {};

TEST_P(PacketFamilyOfCapture, IsItsOwnOrUnknownNeverAnother) {
  RIGCAL_REQUIRE_DATA(path, GetParam().file);
  const PacketFamily own = familyOfModel(GetParam().model);
  ASSERT_NE(own, PacketFamily::kUnknown) << GetParam().model;
  PcapSource source(path);
  std::map<PacketFamily, std::size_t> seen;
  for (std::size_t i = 0; i < 20000; ++i) {
    const auto p = source.next();
    if (!p) break;
    ++seen[recognizePacket(p->payload)];
  }
  for (const auto& [family, count] : seen)
    EXPECT_TRUE(family == own || family == PacketFamily::kUnknown)
        << count << " packets of " << GetParam().file << " taken for " << toString(family);
  if (own == PacketFamily::kOuster) EXPECT_EQ(seen[PacketFamily::kOuster], 0u) << "Ouster has no magic to recognise";
  else EXPECT_GT(seen[own], 100u) << "its data packets are recognised as " << toString(own);
}

INSTANTIATE_TEST_SUITE_P(
    RealCaptures, PacketFamilyOfCapture,
    ::testing::Values(Capture{"velodyne/hdl32e_example.pcap", "HDL-32E"}, Capture{"velodyne/vlp16_dual.pcap", "VLP-16"},
                      Capture{"velodyne/vlp32c_fov270to90.pcap", "VLP-32C"},
                      Capture{"velodyne/vls128_strongest.pcap", "VLS-128"},
                      Capture{"ouster/OS-1-32-G_v2.1.1_1024x10.pcap", "OS1-32"},
                      Capture{"ouster/OS-0-128-U1_v2.3.0_1024x10.pcap", "OS0-128"},
                      Capture{"hesai/pandar40p_dual.pcap", "Pandar40P"}, Capture{"hesai/pandar64_dual.pcap", "Pandar64"},
                      Capture{"hesai/pandarqt64_dual.pcap", "PandarQT64"}, Capture{"hesai/xt32_dual.pcap", "PandarXT32"},
                      Capture{"hesai/qt128_laststrongest.pcap", "PandarQT128"},
                      Capture{"robosense/helios16p.pcap", "RS-Helios-16P"}),
    [](const ::testing::TestParamInfo<Capture>& c) {
      std::string name = c.param.model;
      for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return name;
    });

TEST(PacketFamily, ModelsMapToTheirVendor) {
  EXPECT_EQ(familyOfModel("VLP-16"), PacketFamily::kVelodyne);
  EXPECT_EQ(familyOfModel("RS-Helios-16P"), PacketFamily::kRobosense);
  EXPECT_EQ(familyOfModel("PandarXT32"), PacketFamily::kHesai);
  EXPECT_EQ(familyOfModel("no-such-lidar"), PacketFamily::kUnknown);
}

}  // namespace
}  // namespace rigcal::drivers
