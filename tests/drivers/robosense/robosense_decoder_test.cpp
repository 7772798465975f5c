// RS-Helios-16P decoder behaviour on the real capture: waiting for DIFOP, point times, bad packets.
#include <gtest/gtest.h>

#include <algorithm>

#include "rigcal/drivers/robosense/robosense_decoder.hpp"
#include "robosense_test_util.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

using robosense_test::Capture;

DecoderConfig heliosConfig() {
  DecoderConfig c;
  c.model = "RS-Helios-16P";
  return c;
}

std::size_t difopIndex(const Capture& capture) {
  for (std::size_t i = 0; i < capture.size(); ++i)
    if (robosense::isDifop(capture.payloads[i])) return i;
  return capture.size();
}

TEST(RobosenseDecoder, DataWaitsForTheFirstDifopThenDecodes) {
  RIGCAL_REQUIRE_DATA(path, "robosense/helios16p.pcap");
  const Capture capture = robosense_test::loadCapture(path);
  const std::size_t difop = difopIndex(capture);
  ASSERT_LT(difop, capture.size());
  ASSERT_GT(difop, 0u) << "the capture's DIFOP comes after data packets";
  RobosenseDecoder decoder(heliosConfig());
  DecodedPacket out;
  for (std::size_t i = 0; i < difop; ++i) {
    decoder.decode(capture.packet(i), out);
    EXPECT_EQ(out.kind, DecodedPacket::Kind::kIgnored);
    EXPECT_TRUE(out.points.empty());
  }
  EXPECT_FALSE(decoder.hasAngles());
  EXPECT_EQ(decoder.stats().held_for_difop, difop);
  decoder.decode(capture.packet(difop), out);
  ASSERT_EQ(out.kind, DecodedPacket::Kind::kData);
  EXPECT_TRUE(decoder.hasAngles());
  // Every held packet was decoded: as many points as a decoder that had the DIFOP first.
  RobosenseDecoder informed(heliosConfig());
  DecodedPacket single;
  informed.decode(capture.packet(difop), single);
  std::size_t expected = 0;
  for (std::size_t i = 0; i < difop; ++i) {
    informed.decode(capture.packet(i), single);
    expected += single.points.size();
  }
  EXPECT_GT(expected, difop * 50);
  EXPECT_EQ(out.points.size(), expected);
  EXPECT_EQ(out.points.size(), out.azimuth_deg.size());
  EXPECT_EQ(out.lost_before, 0u);
  // The next data packet follows the batch without a time gap.
  DecodedPacket next;
  decoder.decode(capture.packet(difop + 1), next);
  ASSERT_EQ(next.kind, DecodedPacket::Kind::kData);
  EXPECT_GT(next.packet_time_ns, out.packet_time_ns);
  EXPECT_LT(next.packet_time_ns - out.packet_time_ns, 2 * kNsPerMs);
}

TEST(RobosenseDecoder, TheSourceFilterPassesTheDifopPortBesideTheDataPort) {
  RIGCAL_REQUIRE_DATA(path, "robosense/helios16p.pcap");
  auto count = [&](PacketFilter filter) {
    PcapSource source(path, filter);
    std::size_t n = 0;
    while (source.next()) ++n;
    return n;
  };
  PacketFilter data_only;
  data_only.destination_port = robosense::kDefaultMsopPort;
  PacketFilter both = data_only;
  both.info_port = robosense::kDefaultDifopPort;
  EXPECT_EQ(count(data_only), 750u);
  EXPECT_EQ(count(both), 751u);
}

TEST(RobosenseDecoder, WithoutDifopNoScanIsMadeAndTheDropIsCounted) {
  RIGCAL_REQUIRE_DATA(path, "robosense/helios16p.pcap");
  Capture capture = robosense_test::loadCapture(path);
  const std::size_t difop = difopIndex(capture);
  capture.payloads.erase(capture.payloads.begin() + std::ptrdiff_t(difop));
  capture.receive_ns.erase(capture.receive_ns.begin() + std::ptrdiff_t(difop));
  capture.port.erase(capture.port.begin() + std::ptrdiff_t(difop));
  RobosenseDecoder decoder(heliosConfig());
  const auto scans = robosense_test::decodeScans(decoder, capture);
  EXPECT_TRUE(scans.empty());
  EXPECT_EQ(decoder.stats().dropped_without_difop, capture.size());
}

TEST(RobosenseDecoder, PointTimesFollowTheHeaderClockAndBlockTiming) {
  RIGCAL_REQUIRE_DATA(path, "robosense/helios16p.pcap");
  const Capture capture = robosense_test::loadCapture(path);
  RobosenseDecoder decoder(heliosConfig());
  DecodedPacket out;
  decoder.decode(capture.packet(difopIndex(capture)), out);
  for (std::size_t i = difopIndex(capture) + 1; i < capture.size(); ++i) {
    decoder.decode(capture.packet(i), out);
    ASSERT_EQ(out.kind, DecodedPacket::Kind::kData);
    robosense::MsopView view;
    ASSERT_EQ(robosense::parseMsop(capture.payloads[i], view), "");
    const TimeNs t0 = TimeNs(view.seconds) * kNsPerSec + TimeNs(view.microseconds) * kNsPerUs;
    EXPECT_EQ(out.packet_time_ns, t0);
    for (const Point& p : out.points) {
      EXPECT_GE(p.time_ns, t0);
      EXPECT_LE(p.time_ns, t0 + 11 * 55'560 + 99'460);
    }
  }
  // Sensor clock of this unit: 2017-01-06 (not synchronised), as the header says.
  EXPECT_EQ(out.points.front().time_ns / kNsPerSec, 1483724884);
}

TEST(RobosenseDecoder, SweepsLastOneTurnAndCarryRingsFromTheLowestBeam) {
  RIGCAL_REQUIRE_DATA(path, "robosense/helios16p.pcap");
  RobosenseDecoder decoder(heliosConfig());
  const auto scans = robosense_test::decodeScans(decoder, robosense_test::loadCapture(path));
  ASSERT_GE(scans.size(), 4u);
  const Scan& s = scans[1];
  const auto span = *std::max_element(s.offset_ns.begin(), s.offset_ns.end());
  EXPECT_NEAR(double(span), 100e6, 2e6);  // 600 rpm
  EXPECT_EQ(*std::max_element(s.ring.begin(), s.ring.end()), 15);
  EXPECT_EQ(decoder.scanRateHz(), 10.0);
}

TEST(RobosenseDecoder, MalformedAndForeignPacketsAreRejectedWithTheirField) {
  RIGCAL_REQUIRE_DATA(path, "robosense/helios16p.pcap");
  const Capture capture = robosense_test::loadCapture(path);
  const std::size_t difop = difopIndex(capture);
  const std::vector<std::uint8_t> good_msop = capture.payloads[difop + 1];
  const std::vector<std::uint8_t> good_difop = capture.payloads[difop];

  RobosenseDecoder decoder(heliosConfig());
  DecodedPacket out;
  auto decode = [&](const std::vector<std::uint8_t>& bytes) {
    UdpPacket p;
    p.payload = bytes;
    decoder.decode(p, out);
  };
  auto expectMalformed = [&](std::vector<std::uint8_t> bytes, const std::string& field) {
    decode(bytes);
    EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed) << field;
    EXPECT_NE(out.error.find(field), std::string::npos) << out.error;
    EXPECT_TRUE(out.points.empty());
  };
  expectMalformed({good_msop.begin(), good_msop.begin() + 1000}, "size 1000");
  expectMalformed(std::vector<std::uint8_t>(1206, 0), "size 1206");  // a Velodyne-sized datagram
  auto bad = good_msop;
  bad[0] = 0x12;
  expectMalformed(bad, "header id");
  bad = good_msop;
  bad[robosense::kHeaderSize + 5 * robosense::kBlockSize + 1] = 0x00;
  expectMalformed(bad, "block 5 id");
  bad = good_msop;
  bad[robosense::kHeaderSize + 2 * robosense::kBlockSize + 2] = 0xFF;  // azimuth ≥ 360°
  expectMalformed(bad, "block 2 azimuth");
  bad = good_msop;
  bad[robosense::kTimestampOffset + 6] = 0xFF;  // µs field ≥ 1e6
  expectMalformed(bad, "µs field");
  // fuzz_robosense_decoder: a u48 seconds field past int64 nanoseconds overflowed the packet time (UB).
  bad = good_msop;
  for (int i = 0; i < 6; ++i) bad[robosense::kTimestampOffset + i] = 0xFF;
  expectMalformed(bad, "seconds field");
  expectMalformed({good_difop.begin(), good_difop.end() - 1}, "DIFOP packet: size 1247");
  bad = good_difop;
  bad[468 + 3 * 4] = 0xFF;
  expectMalformed(bad, "vertical angle of laser 4");
  bad = good_difop;
  bad[564 + 3 * 7 + 1] = 0x40;  // 163.84° offset
  expectMalformed(bad, "horizontal angle of laser 7");
  EXPECT_FALSE(decoder.hasAngles()) << "a bad DIFOP leaves the angles unknown";
  // The decoder still works afterwards.
  decode(good_difop);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kIgnored);
  decode(good_msop);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kData);
  EXPECT_FALSE(out.points.empty());
}

TEST(RobosenseDecoder, DualReturnModeMarksTheSecondHalfOfEachBlockAsSecondReturn) {
  RIGCAL_REQUIRE_DATA(path, "robosense/helios16p.pcap");
  const Capture capture = robosense_test::loadCapture(path);
  std::vector<std::uint8_t> difop = capture.payloads[difopIndex(capture)];
  difop[300] = 0x00;  // return mode: dual
  RobosenseDecoder decoder(heliosConfig());
  DecodedPacket out;
  UdpPacket p;
  p.payload = difop;
  decoder.decode(p, out);
  std::size_t second = 0, total = 0;
  for (std::size_t i = difopIndex(capture) + 1; i < capture.size(); ++i) {
    decoder.decode(capture.packet(i), out);
    ASSERT_EQ(out.kind, DecodedPacket::Kind::kData);
    total += out.points.size();
    for (const Point& q : out.points) {
      second += q.return_index == 1;
      // Paired blocks fire together: no point is later than the last pair's firing.
      EXPECT_LE(q.time_ns - out.packet_time_ns, 5 * 55'560 + 43'910);
    }
  }
  EXPECT_GT(second, 0u);
  EXPECT_LT(second, total);
}

TEST(RobosenseDecoder, RefusesOtherModelsAndCalibrationFiles) {
  DecoderConfig c = heliosConfig();
  c.model = "RS-Helios-32";
  EXPECT_THROW(RobosenseDecoder{c}, std::runtime_error);
  c = heliosConfig();
  c.calibration = "angle.csv";
  EXPECT_THROW(RobosenseDecoder{c}, std::runtime_error);
  EXPECT_NO_THROW(makeDecoder(heliosConfig()));
}

}  // namespace
}  // namespace rigcal::drivers
