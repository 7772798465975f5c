// PacketRestamper on real captures (../shared/data): a restamped packet still decodes (CRCs rewritten),
// and every point's time moves by exactly the shift when the receiver's clock moves with it (a replay:
// the capture's receive times become "now").
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "rigcal/drivers/hesai/hesai_packet.hpp"
#include "rigcal/drivers/packet_restamper.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/robosense/robosense_packet.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

// Three years, five hours and a fraction of a second: crosses the top of the hour and days, months, years.
constexpr std::int64_t kShiftUs = (3LL * 365 * 24 + 5) * 3'600'000'000LL + 1'234'567;

struct Counts {
  int restamped = 0, data = 0;
};

Counts checkShift(const std::filesystem::path& pcap, const DecoderConfig& config, std::int64_t shift_us,
                  PacketFilter filter = {}) {
  Counts n;
  const PacketRestamper restamper(config);
  auto original = makeDecoder(config);
  auto shifted = makeDecoder(config);
  PcapSource source(pcap, filter);
  DecodedPacket a, b;
  std::vector<std::uint8_t> payload;
  while (auto p = source.next()) {
    payload.assign(p->payload.begin(), p->payload.end());
    const bool restamped = restamper.restamp(payload, shift_us);
    n.restamped += restamped ? 1 : 0;
    original->decode(*p, a);
    UdpPacket moved = *p;
    moved.payload = payload;
    moved.receive_ns += shift_us * 1000;
    shifted->decode(moved, b);
    EXPECT_EQ(int(b.kind), int(a.kind)) << pcap.filename() << ": " << b.error;
    if (a.kind != DecodedPacket::Kind::kData) {
      EXPECT_FALSE(restamped && a.kind == DecodedPacket::Kind::kIgnored && payload != std::vector<std::uint8_t>(
                                                                                  p->payload.begin(), p->payload.end()))
          << "a packet without points was rewritten";
      continue;
    }
    EXPECT_TRUE(restamped) << pcap.filename() << ": a data packet was not restamped";
    ++n.data;
    EXPECT_EQ(b.packet_time_ns - a.packet_time_ns, shift_us * 1000) << pcap.filename();
    EXPECT_EQ(a.points.size(), b.points.size());
    if (a.points.size() != b.points.size()) break;
    for (std::size_t i = 0; i < a.points.size(); ++i)
      if (b.points[i].time_ns - a.points[i].time_ns != shift_us * 1000) {
        ADD_FAILURE() << pcap.filename() << ": point " << i << " moved by " << b.points[i].time_ns - a.points[i].time_ns;
        break;
      }
  }
  return n;
}

TEST(PacketRestamper, VelodyneMicrosecondsPastTheHourMoveWithTheReceiverClock) {
  RIGCAL_REQUIRE_DATA(vlp16, "velodyne/vlp16_dual.pcap");
  RIGCAL_REQUIRE_DATA(hdl32, "velodyne/hdl32e_example.pcap");
  DecoderConfig c;
  c.model = "VLP-16";
  const Counts v = checkShift(vlp16, c, kShiftUs);
  EXPECT_GT(v.data, 50);
  c.model = "HDL-32E";
  const Counts h = checkShift(hdl32, c, -kShiftUs);  // backwards too
  EXPECT_GT(h.data, 50);
}

TEST(PacketRestamper, OusterColumnTimestampsAndCrcFooter) {
  RIGCAL_REQUIRE_DATA(os2, "ouster/OS-2-128-U1_v2.3.0_1024x10.pcap");
  RIGCAL_REQUIRE_DATA(crc, "ouster/crc_test.pcap");
  DecoderConfig c;
  c.model = "OS2-128";
  c.metadata = test::dataDir() / "ouster/OS-2-128-U1_v2.3.0_1024x10.json";
  EXPECT_GT(checkShift(os2, c, kShiftUs).data, 10);
  // Firmware 3.2: the footer's CRC-64 covers the timestamps and is rewritten (a stale one is malformed).
  c.model = "OS0-128";
  c.metadata = test::dataDir() / "ouster/crc_test.json";
  EXPECT_GT(checkShift(crc, c, -kShiftUs).data, 10);
}

TEST(PacketRestamper, HesaiTailDateAndCrc) {
  RIGCAL_REQUIRE_DATA(xt32, "hesai/xt32_dual.pcap");
  RIGCAL_REQUIRE_DATA(qt128, "hesai/qt128_laststrongest.pcap");
  DecoderConfig c;
  c.model = "PandarXT32";
  EXPECT_GT(checkShift(xt32, c, kShiftUs).data, 10);
  c.model = "PandarQT128";
  c.calibration = test::dataDir() / "hesai/PandarQT128.csv";
  EXPECT_GT(checkShift(qt128, c, -kShiftUs).data, 10);
  // The decoder only counts CRC mismatches: check the rewritten tail CRC (protocol 3.2) directly.
  const PacketRestamper restamper(c);
  PcapSource source(qt128);
  int checked = 0;
  while (auto p = source.next()) {
    std::vector<std::uint8_t> payload(p->payload.begin(), p->payload.end());
    hesai::PacketView before, after;
    if (!hesai::parsePacket(*hesai::findModel("PandarQT128"), payload, before).empty() || !before.crc_ok) continue;
    ASSERT_TRUE(restamper.restamp(payload, kShiftUs));
    ASSERT_EQ(hesai::parsePacket(*hesai::findModel("PandarQT128"), payload, after), "");
    EXPECT_TRUE(after.crc_ok);
    EXPECT_NE(after.timestamp_us, before.timestamp_us);
    ++checked;
  }
  EXPECT_GT(checked, 10);
}

// The older Hesai formats put the µs timestamp before the date; the Pandar40P capture counts years from
// 2000, the Pandar64 one from 1900: a wrong offset or year base would move the decoded times by other
// than the shift.
TEST(PacketRestamper, HesaiPandar40P64QT64AndXT32MTailTimes) {
  struct Case {
    const char* model;
    const char* capture;
    const char* calibration;
  };
  int n = 0;
  for (const Case& k : {Case{"Pandar40P", "hesai/pandar40p_dual.pcap", "hesai/Pandar40P.csv"},
                        Case{"Pandar64", "hesai/pandar64_dual.pcap", "hesai/Pandar64.csv"},
                        Case{"PandarQT64", "hesai/pandarqt64_dual.pcap", "hesai/PandarQT64.csv"},
                        Case{"PandarXT32M", "hesai/xt32m_laststrongest.pcap", "hesai/PandarXT32M.csv"}}) {
    RIGCAL_REQUIRE_DATA(pcap, k.capture);
    DecoderConfig c;
    c.model = k.model;
    c.calibration = test::dataDir() / k.calibration;
    EXPECT_GT(checkShift(pcap, c, (n++ % 2) ? -kShiftUs : kShiftUs).data, 500) << k.model;
  }
}

TEST(PacketRestamper, RobosenseMsopHeaderTime) {
  RIGCAL_REQUIRE_DATA(helios, "robosense/helios16p.pcap");
  DecoderConfig c;
  c.model = "RS-Helios-16P";
  const PacketRestamper restamper(c);
  std::vector<std::vector<std::uint8_t>> payloads;
  PcapSource source(helios);
  while (auto p = source.next()) payloads.emplace_back(p->payload.begin(), p->payload.end());
  // Both decoders get the (unchanged) DIFOP first, so every data packet decodes at once.
  const auto difop = std::find_if(payloads.begin(), payloads.end(), [](const auto& p) { return robosense::isDifop(p); });
  ASSERT_NE(difop, payloads.end());
  auto original = makeDecoder(c);
  auto shifted = makeDecoder(c);
  DecodedPacket a, b;
  UdpPacket packet;
  std::vector<std::uint8_t> info = *difop;
  EXPECT_FALSE(restamper.restamp(info, kShiftUs));
  EXPECT_EQ(info, *difop) << "DIFOP is left as it was";
  packet.payload = info;
  original->decode(packet, a);
  shifted->decode(packet, b);
  int data = 0;
  for (const auto& payload : payloads) {
    if (robosense::isDifop(payload)) continue;
    std::vector<std::uint8_t> moved = payload;
    ASSERT_TRUE(restamper.restamp(moved, -kShiftUs));
    packet.payload = payload;
    original->decode(packet, a);
    packet.payload = moved;
    shifted->decode(packet, b);
    ASSERT_EQ(a.kind, DecodedPacket::Kind::kData);
    ASSERT_EQ(b.kind, DecodedPacket::Kind::kData) << b.error;
    EXPECT_EQ(b.packet_time_ns - a.packet_time_ns, -kShiftUs * 1000);
    ASSERT_EQ(a.points.size(), b.points.size());
    for (std::size_t i = 0; i < a.points.size(); ++i) ASSERT_EQ(b.points[i].time_ns - a.points[i].time_ns, -kShiftUs * 1000);
    ++data;
  }
  EXPECT_EQ(data, int(payloads.size()) - 1);
}

TEST(PacketRestamper, ForeignPacketsAndUnknownModelsAreLeftAlone) {
  DecoderConfig c;
  c.model = "VLP-16";
  const PacketRestamper velodyne(c);
  std::vector<std::uint8_t> position(512, 0x42);
  const auto before = position;
  EXPECT_FALSE(velodyne.restamp(position, kShiftUs));
  EXPECT_EQ(position, before);
  c.model = "OS1-64";
  EXPECT_THROW(PacketRestamper{c}, std::runtime_error);  // no metadata: says so
  c.model = "LD-9000";
  try {
    const PacketRestamper unknown(c);
    ADD_FAILURE() << "an unknown model was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("LD-9000"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigcal::drivers
