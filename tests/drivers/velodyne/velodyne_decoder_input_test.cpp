// Velodyne decoder input checks: position packets ignored, malformed and foreign packets rejected naming
// the field, random bytes never crash.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "packet_builder.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"
#include "test_data.hpp"
#include "velodyne_decoder_helpers.hpp"

namespace rigcal::drivers {
namespace {

using namespace test_velodyne;
using test::VelodynePacketBuilder;

TEST(VelodyneDecoder, PositionPacketsAreIgnored) {
  auto d = decoder("HDL-32E");
  std::vector<std::uint8_t> bytes(512, 0);
  UdpPacket p;
  p.payload = bytes;
  p.destination.port = 8308;
  DecodedPacket out;
  d->decode(p, out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kIgnored);
  EXPECT_TRUE(out.points.empty());
}

TEST(VelodyneDecoder, MalformedPacketsNameTheField) {
  auto d = decoder("VLP-16");
  const VelodynePacketBuilder good(0x22, 0x37, 1000);
  expectMalformed(*d, {}, "VLP-16 packet: size 0, expected 1206");
  expectMalformed(*d, std::vector<std::uint8_t>(good.bytes.begin(), good.bytes.end() - 1), "size 1205");
  auto longer = good.bytes;
  longer.push_back(0);
  expectMalformed(*d, longer, "size 1207");

  VelodynePacketBuilder b = good;
  b.setHeader(7, 0xDDFF);
  expectMalformed(*d, b.bytes, "block 7 header 0xDDFF");
  b = good;
  b.setAzimuth(3, 36001);
  expectMalformed(*d, b.bytes, "block 3 azimuth 36001");
  b = good;
  b.bytes[1205] = 0x28;
  expectMalformed(*d, b.bytes, "product id 0x28 (VLP-32C)");
  b = good;
  b.bytes[1204] = 0x42;
  expectMalformed(*d, b.bytes, "return mode byte 0x42");
  b = good;
  b.setTimestamp(3'600'000'000u);
  expectMalformed(*d, b.bytes, "timestamp 3600000000 us");

  // The same bytes decode once fixed: the decoder kept no bad state.
  UdpPacket p = good.packet(kHourStart);
  DecodedPacket out;
  d->decode(p, out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kData);
}

TEST(VelodyneDecoder, ForeignPacketFromAnotherSensorIsMalformed) {
  RIGCAL_REQUIRE_DATA(path, "ouster/VLI-16-one-packet.pcap");
  PcapSource source(path);
  auto d = decoder("VLP-16");
  int n = 0;
  while (auto p = source.next()) {
    DecodedPacket out;
    d->decode(*p, out);
    EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed);
    EXPECT_NE(out.error.find("size 1212"), std::string::npos) << out.error;
    ++n;
  }
  EXPECT_EQ(n, 1);
}

TEST(VelodyneDecoder, RandomBytesNeverCrash) {
  std::mt19937 rng(7);
  for (const std::string model : {"VLP-16", "VLP-32C", "HDL-32E"}) {
    auto d = decoder(model);
    DecodedPacket out;
    for (int i = 0; i < 2000; ++i) {
      std::vector<std::uint8_t> bytes(i % 3 == 0 ? rng() % 1400 : 1206);
      for (auto& v : bytes) v = static_cast<std::uint8_t>(rng());
      if (i % 2 && bytes.size() == 1206) {  // valid framing, random content
        for (int b = 0; b < 12; ++b) {
          bytes[b * 100] = 0xFF;
          bytes[b * 100 + 1] = 0xEE;
          bytes[b * 100 + 3] = static_cast<std::uint8_t>(rng() % 0x8C);
        }
        bytes[1204] = 0x37 + static_cast<std::uint8_t>(rng() % 3);
        bytes[1205] = 0;
        bytes[1203] = 0;
      }
      UdpPacket p;
      p.payload = bytes;
      p.receive_ns = static_cast<TimeNs>(rng()) * 1000;
      d->decode(p, out);
      if (bytes.size() != 512) {
        ASSERT_NE(out.kind, DecodedPacket::Kind::kIgnored);
      }
      EXPECT_EQ(out.points.size(), out.azimuth_deg.size());
      if (out.kind == DecodedPacket::Kind::kMalformed) {
        EXPECT_FALSE(out.error.empty());
      }
      for (const Point& pt : out.points) ASSERT_TRUE(std::isfinite(pt.x) && std::isfinite(pt.y) && std::isfinite(pt.z));
    }
  }
}

}  // namespace
}  // namespace rigcal::drivers
