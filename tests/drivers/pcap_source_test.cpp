#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
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

// Rewrites a classic little-endian microsecond pcap as pcapng (SHB, IDB, one EPB per record).
void convertToPcapng(const std::filesystem::path& in, const std::filesystem::path& out) {
  std::ifstream src(in, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(src)), {});
  std::uint32_t magic, linktype, snaplen;
  std::memcpy(&magic, bytes.data(), 4);
  ASSERT_EQ(magic, 0xa1b2c3d4u) << "test expects a little-endian microsecond pcap";
  std::memcpy(&snaplen, bytes.data() + 16, 4);
  std::memcpy(&linktype, bytes.data() + 20, 4);
  std::ofstream dst(out, std::ios::binary);
  const auto u32 = [&](std::uint32_t v) { dst.write(reinterpret_cast<const char*>(&v), 4); };
  const auto u16 = [&](std::uint16_t v) { dst.write(reinterpret_cast<const char*>(&v), 2); };
  u32(0x0A0D0D0A), u32(28), u32(0x1A2B3C4D), u16(1), u16(0), u32(0xffffffff), u32(0xffffffff), u32(28);
  u32(1), u32(20), u16(std::uint16_t(linktype)), u16(0), u32(snaplen), u32(20);
  for (std::size_t off = 24; off + 16 <= bytes.size();) {
    std::uint32_t sec, usec, caplen, origlen;
    std::memcpy(&sec, &bytes[off], 4);
    std::memcpy(&usec, &bytes[off + 4], 4);
    std::memcpy(&caplen, &bytes[off + 8], 4);
    std::memcpy(&origlen, &bytes[off + 12], 4);
    const std::uint64_t ts = std::uint64_t(sec) * 1000000 + usec;  // default if_tsresol: µs
    const std::uint32_t padded = (caplen + 3) & ~3u;
    const std::uint32_t total = 32 + padded;
    u32(6), u32(total), u32(0), u32(std::uint32_t(ts >> 32)), u32(std::uint32_t(ts)), u32(caplen), u32(origlen);
    dst.write(&bytes[off + 16], caplen);
    for (std::uint32_t p = caplen; p < padded; ++p) dst.put(0);
    u32(total);
    off += 16 + caplen;
  }
}

TEST(PcapSource, ReadsPcapngLikeClassicPcap) {
  RIGCAL_REQUIRE_DATA(path, "ouster/OS-1-32-G_v2.1.1_1024x10.pcap");
  test::TempDir dir;
  convertToPcapng(path, dir / "same.pcapng");
  PcapSource classic(path), ng(dir / "same.pcapng");
  std::size_t n = 0;
  while (auto a = classic.next()) {
    const std::vector<std::uint8_t> pa(a->payload.begin(), a->payload.end());
    const TimeNs ta = a->receive_ns;
    auto b = ng.next();
    ASSERT_TRUE(b.has_value()) << "datagram " << n;
    EXPECT_EQ(std::vector<std::uint8_t>(b->payload.begin(), b->payload.end()), pa) << n;
    EXPECT_EQ(b->receive_ns, ta) << n;
    ++n;
  }
  EXPECT_FALSE(ng.next().has_value());
  EXPECT_GT(n, 60u);  // fragmented datagrams reassemble from pcapng too
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
