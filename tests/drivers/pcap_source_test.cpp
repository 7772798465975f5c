#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "rigcal/drivers/pcap_source.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

std::size_t countPackets(PcapSource& source, std::set<std::size_t>* sizes = nullptr) {
  std::size_t n = 0;
  while (auto p = source.next()) {
    ++n;
    if (sizes) sizes->insert(p->payload.size());
  }
  return n;
}

TEST(PcapSource, ReassemblesFragmentedOusterPackets) {
  RIGCAL_REQUIRE_DATA(path, "ouster/OS-1-32-G_v2.1.1_1024x10.pcap");
  PcapSource source(path, PacketFilter{7502, std::nullopt});
  std::set<std::size_t> sizes;
  const std::size_t n = countPackets(source, &sizes);
  // One 1024-column frame at 16 columns per packet: 64 lidar packets of one fixed size.
  EXPECT_EQ(n, 64u);
  EXPECT_EQ(sizes.size(), 1u);
  EXPECT_GT(*sizes.begin(), 1500u) << "reassembled datagrams exceed the MTU";
  EXPECT_EQ(source.stats().fragments_dropped, 0u);
  EXPECT_TRUE(source.warning().empty());
}

TEST(PcapSource, SeparatesTwoSensorsOnOnePortBySourceAddress) {
  RIGCAL_REQUIRE_DATA(path, "ouster/same_ports.pcap");
  std::set<std::uint32_t> sources;
  {
    PcapSource all(path, PacketFilter{7502, std::nullopt});
    while (auto p = all.next()) sources.insert(p->source.address);
  }
  ASSERT_EQ(sources.size(), 2u);
  std::size_t total = 0;
  for (std::uint32_t src : sources) {
    PcapSource one(path, PacketFilter{7502, src});
    const std::size_t n = countPackets(one);
    EXPECT_GT(n, 0u);
    EXPECT_EQ(one.stats().filtered + n, one.stats().filtered + one.stats().packets);
    total += n;
  }
  PcapSource all(path, PacketFilter{7502, std::nullopt});
  EXPECT_EQ(countPackets(all), total);
}

TEST(PcapSource, EmptyCaptureYieldsNothingWithoutError) {
  RIGCAL_REQUIRE_DATA(path, "ouster/empty_pcap.pcap");
  PcapSource source(path);
  EXPECT_FALSE(source.next().has_value());
  EXPECT_TRUE(source.warning().empty());
}

TEST(PcapSource, TruncatedCaptureKeepsPacketsBeforeTheCutAndWarns) {
  RIGCAL_REQUIRE_DATA(path, "velodyne/vlp16_dual.pcap");
  std::size_t full = 0;
  {
    PcapSource source(path);
    full = countPackets(source);
  }
  test::TempDir dir;
  const auto cut = dir / "cut.pcap";
  std::filesystem::copy_file(path, cut);
  std::filesystem::resize_file(cut, std::filesystem::file_size(cut) / 2 + 7);
  PcapSource source(cut);
  const std::size_t n = countPackets(source);
  EXPECT_GT(n, full / 3);
  EXPECT_LT(n, full);
  EXPECT_NE(source.warning().find("cut.pcap"), std::string::npos) << source.warning();
  EXPECT_EQ(source.warning().find('\n'), std::string::npos);
}

TEST(PcapSource, NonCaptureFileIsRefusedNamingIt) {
  test::TempDir dir;
  std::ofstream(dir / "notes.pcap") << "definitely not a capture";
  try {
    PcapSource source(dir / "notes.pcap");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("notes.pcap"), std::string::npos) << e.what();
  }
  EXPECT_THROW(PcapSource(dir / "missing.pcap"), std::runtime_error);
}

TEST(PcapSource, ReadsVelodyneDataAndPositionPacketsByPort) {
  RIGCAL_REQUIRE_DATA(path, "velodyne/vlp16_20hz_veloview.pcap");
  PcapSource data(path, PacketFilter{2368, std::nullopt});
  std::set<std::size_t> sizes;
  EXPECT_GT(countPackets(data, &sizes), 1000u);
  EXPECT_EQ(sizes, std::set<std::size_t>{1206});
  PcapSource position(path, PacketFilter{8308, std::nullopt});
  std::set<std::size_t> psizes;
  EXPECT_GT(countPackets(position, &psizes), 0u);
  EXPECT_EQ(psizes, std::set<std::size_t>{512});
}

}  // namespace
}  // namespace rigcal::drivers
