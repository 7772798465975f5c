// Velodyne decoder time: per-firing offsets per model, the host clock, the hour taken from the receive time,
// lost packets counted from timestamps, the dead sector of a limited field of view, the scan size bound.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "packet_builder.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"
#include "test_data.hpp"
#include "velodyne_decoder_helpers.hpp"

namespace rigcal::drivers {
namespace {

using namespace test_velodyne;
using test::VelodynePacketBuilder;
using velodyne::firingOffsetUs;
using velodyne::HourResolver;
using velodyne::Model;

TEST(VelodyneDecoder, FiringTimesFollowTheManual) {
  struct Case {
    std::string model;
    std::uint8_t product, mode;
    Model m;
  };
  for (const Case& k : {Case{"VLP-16", 0x22, 0x37, Model::kVlp16}, Case{"VLP-16", 0x22, 0x39, Model::kVlp16},
                        Case{"VLP-32C", 0x28, 0x37, Model::kVlp32c}, Case{"VLP-32C", 0x28, 0x39, Model::kVlp32c},
                        Case{"HDL-32E", 0x21, 0x37, Model::kHdl32e}, Case{"HDL-32E", 0x21, 0x39, Model::kHdl32e}}) {
    const bool dual = k.mode == 0x39;
    auto d = decoder(k.model);
    const std::uint32_t micros = 1234'567'890u;  // 20 min 34.56789 s past the hour
    VelodynePacketBuilder b(k.product, k.mode, micros);
    b.rampAzimuth(100, 20, dual ? 2 : 1).fill(2000);
    if (dual)  // distinct second returns, so both blocks of each pair give points
      for (int blk = 1; blk < 12; blk += 2)
        for (int c = 0; c < 32; ++c) b.setReturn(blk, c, 2100, 5);
    DecodedPacket out;
    d->decode(b.packet(kHourStart + 1234 * kNsPerSec), out);
    ASSERT_EQ(out.points.size(), 384u) << k.model;
    const TimeNs t0 = kHourStart + TimeNs(micros) * kNsPerUs;
    // The packet's first firing: the stamp itself, except the HDL-32E (stamped at its last firing).
    EXPECT_EQ(out.packet_time_ns, t0 + std::llround(firingOffsetUs(k.m, dual, 0, 0, 0) * 1000)) << k.model;
    if (k.m != Model::kHdl32e) {
      EXPECT_EQ(out.packet_time_ns, t0);
    }
    for (int blk = 0; blk < 12; ++blk)
      for (int c = 0; c < 32; ++c) {
        const Point& p = out.points[blk * 32 + c];
        EXPECT_EQ(p.time_ns, t0 + std::llround(firingOffsetUs(k.m, dual, blk, 0, c) * 1000)) << k.model << blk << c;
        EXPECT_EQ(p.return_index, dual ? blk % 2 : 0);
      }
  }
}

TEST(VelodyneDecoder, Vls128FiringTimesAndBanks) {
  RIGCAL_REQUIRE_DATA(calibration, "velodyne/VLS128.calibration.yaml");
  DecoderConfig config;
  config.model = "VLS-128";
  config.calibration = calibration;
  auto d = makeVelodyneDecoder(config);
  VelodynePacketBuilder b(0xA1, 0x37, 5'000'000u);
  for (int blk = 0; blk < 12; ++blk) b.setHeader(blk, velodyne::kBankHeaders[blk % 4]);
  b.rampAzimuth(500, 20, 4).fill(2500);
  DecodedPacket out;
  d->decode(b.packet(kHourStart + 5 * kNsPerSec), out);
  ASSERT_EQ(out.points.size(), 384u);
  const TimeNs t0 = kHourStart + 5 * kNsPerSec;
  for (int blk = 0; blk < 12; ++blk)
    for (int c = 0; c < 32; ++c) {
      const Point& p = out.points[blk * 32 + c];
      EXPECT_EQ(p.ring, (blk % 4) * 32 + c);
      EXPECT_EQ(p.time_ns, t0 + std::llround(firingOffsetUs(Model::kVls128, false, blk, blk % 4, c) * 1000));
    }
  EXPECT_EQ(out.packet_time_ns, t0 - 8700);  // the first firing precedes the packet stamp by 8.7 µs
  // A bank header out of the four is malformed.
  b.setHeader(5, 0xAAFF);
  d->decode(b.packet(kHourStart + 5 * kNsPerSec), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed);
  EXPECT_NE(out.error.find("block 5 header 0xAAFF"), std::string::npos) << out.error;
}

TEST(VelodyneDecoder, HostClockReplacesThePacketTime) {
  VelodynePacketBuilder b(0x22, 0x37, 1'000'000u);  // 1 s past the hour
  b.rampAzimuth(0, 40).fill(3000);
  const TimeNs receive = kHourStart + 1800 * kNsPerSec + 123;  // host clock 30 min off the sensor's
  DecodedPacket sensor, host;
  decoder("VLP-16", TimeSource::kSensorClock)->decode(b.packet(receive), sensor);
  decoder("VLP-16", TimeSource::kHostReceive)->decode(b.packet(receive), host);
  ASSERT_EQ(sensor.points.size(), host.points.size());
  EXPECT_EQ(sensor.packet_time_ns, kHourStart + kNsPerSec);
  EXPECT_EQ(host.packet_time_ns, receive);
  for (std::size_t i = 0; i < host.points.size(); ++i)
    EXPECT_EQ(host.points[i].time_ns - receive, sensor.points[i].time_ns - (kHourStart + kNsPerSec));
}

TEST(VelodyneHourResolver, FirstPacketTakesTheNearestHour) {
  // Sensor at 59:59.9, host just after the top of the hour: the previous hour.
  HourResolver a;
  EXPECT_EQ(a.resolve(3'599'900'000u, kHourStart + 50 * kNsPerMs), kHourStart - 100 * kNsPerMs);
  // Sensor at 00:00.05, host just before the top of the hour: the next hour.
  HourResolver b;
  EXPECT_EQ(b.resolve(50'000u, kHourStart - 50 * kNsPerMs), kHourStart + 50 * kNsPerMs);
  // Same hour.
  HourResolver c;
  EXPECT_EQ(c.resolve(1'000'000'000u, kHourStart + 1000 * kNsPerSec + 3 * kNsPerMs), kHourStart + 1000 * kNsPerSec);
}

TEST(VelodyneHourResolver, WrapsForwardAndBackward) {
  HourResolver r;
  const TimeNs offset = 20 * 60 * kNsPerSec;  // a host clock 20 minutes ahead of the sensor
  TimeNs t = r.resolve(3'599'999'000u, kHourStart - 1000 + offset);
  EXPECT_EQ(t, kHourStart - 1 * kNsPerMs);
  // The sensor's count wraps to 0 at its top of the hour: time goes on forward.
  t = r.resolve(300u, kHourStart + 300 * kNsPerUs + offset);
  EXPECT_EQ(t, kHourStart + 300 * kNsPerUs);
  // A packet from before the wrap arriving late belongs to the previous hour.
  t = r.resolve(3'599'999'500u, kHourStart + 400 * kNsPerUs + offset);
  EXPECT_EQ(t, kHourStart - 500 * kNsPerUs);
  // ... and the stream continues in the new hour.
  t = r.resolve(1'000u, kHourStart + 1 * kNsPerMs + offset);
  EXPECT_EQ(t, kHourStart + 1 * kNsPerMs);
  // Hours later (a jump of the reference clock re-anchors).
  t = r.resolve(1'000u, kHourStart + 5 * kHour + offset);
  EXPECT_EQ(t, kHourStart + 5 * kHour + 1 * kNsPerMs);
}

TEST(VelodyneDecoder, HourWrapInThePacketStream) {
  auto d = decoder("VLP-16");
  const TimeNs period = 1'327'104;
  DecodedPacket out;
  std::uint32_t micros = 3'599'998'000u;
  TimeNs receive = kHourStart - 2 * kNsPerMs + 1'400'000;
  TimeNs last = 0;
  for (int i = 0; i < 4; ++i) {  // four packets straddling the top of the hour
    VelodynePacketBuilder b(0x22, 0x37, micros);
    b.rampAzimuth(i * 960, 80).fill(3000);
    d->decode(b.packet(receive), out);
    ASSERT_EQ(out.kind, DecodedPacket::Kind::kData);
    if (i > 0) {
      EXPECT_NEAR(double(out.packet_time_ns - last), double(period), 1000.0);
    }
    EXPECT_EQ(out.lost_before, 0u);
    last = out.packet_time_ns;
    micros = static_cast<std::uint32_t>((micros + 1327u) % velodyne::kMicrosPerHour);
    receive += period;
  }
  EXPECT_GT(last, kHourStart);
}

TEST(VelodyneDecoder, LostPacketsAreCountedFromTimestamps) {
  for (const bool dual : {false, true}) {
    auto d = decoder("VLP-16");
    const double period_us = dual ? 663.552 : 1327.104;
    const int step = 40;  // per sequence (block or pair)
    const int per_packet = dual ? 6 : 12;
    DecodedPacket out;
    std::vector<std::uint32_t> lost;
    for (int i = 0; i < 40; ++i) {
      if (i == 10 || i == 20 || i == 21 || i == 22) continue;  // dropped on the way
      const auto micros = static_cast<std::uint32_t>(1'000'000 + std::llround(i * period_us));
      VelodynePacketBuilder b(0x22, dual ? 0x39 : 0x37, micros);
      b.rampAzimuth(i * per_packet * step, step, dual ? 2 : 1).fill(3000);
      d->decode(b.packet(kHourStart + TimeNs(micros) * 1000 + 5 * kNsPerMs), out);
      lost.push_back(out.lost_before);
    }
    std::uint32_t total = 0;
    for (auto l : lost) total += l;
    EXPECT_EQ(total, 4u) << dual;
    EXPECT_EQ(lost[10], 1u);
    EXPECT_EQ(lost[19], 3u);  // packet 23, after 20..22
    EXPECT_NEAR(d->scanRateHz(), step / 36000.0 / (period_us / per_packet * 1e-6), 0.05);
  }
}

TEST(VelodyneDecoder, LimitedFieldOfViewJumpIsTimedAndNotALoss) {
  // VLP-32C with its field of view limited to 270°→90° at 10 Hz: one packet holds the last blocks
  // before 90° and the first after 270°, which fired ~50 ms later.
  auto d = decoder("VLP-32C");
  const double block_us = 55.296;
  DecodedPacket out;
  // Packet A: blocks at 89.56°.. then (block 8 on) at 270.17°..
  VelodynePacketBuilder a(0x28, 0x37, 1'000'000u);
  for (int blk = 0; blk < 8; ++blk) a.setAzimuth(blk, static_cast<std::uint16_t>(8956 + 20 * blk));
  for (int blk = 8; blk < 12; ++blk) a.setAzimuth(blk, static_cast<std::uint16_t>(27017 + 20 * (blk - 8)));
  a.fill(3000);
  d->decode(a.packet(kHourStart + kNsPerSec + 50 * kNsPerMs), out);
  ASSERT_EQ(out.kind, DecodedPacket::Kind::kData);
  const TimeNs jump_ns = std::llround((27017 - (8956 + 20 * 7) - 20) / 20.0 * block_us * 1000);
  EXPECT_EQ(out.points[8 * 32].time_ns - out.points[7 * 32].time_ns, std::llround(block_us * 1000) + jump_ns);
  // Packet B follows the post-jump blocks of A; its stamp is ~50 ms after A's.
  const auto micros_b = static_cast<std::uint32_t>(1'000'000 + std::llround(12 * block_us + jump_ns / 1000.0));
  VelodynePacketBuilder b(0x28, 0x37, micros_b);
  b.rampAzimuth(27097, 20).fill(3000);
  d->decode(b.packet(kHourStart + kNsPerSec + 51 * kNsPerMs), out);
  EXPECT_EQ(out.lost_before, 0u);
  // The dead sector falling exactly between two packets is not a loss either, once seen.
  VelodynePacketBuilder c(0x28, 0x37, micros_b + 664);
  for (int blk = 0; blk < 12; ++blk) c.setAzimuth(blk, static_cast<std::uint16_t>(8856 + 20 * blk));
  c.fill(3000);
  // (Packet C just brings the rotor back before the dead sector; what matters is the next packet.)
  d->decode(c.packet(kHourStart + kNsPerSec + 52 * kNsPerMs), out);
  VelodynePacketBuilder e(0x28, 0x37, micros_b + 664 + std::uint32_t(std::llround(12 * block_us + jump_ns / 1000.0)));
  e.rampAzimuth(27017 + 60, 20).fill(3000);
  d->decode(e.packet(kHourStart + kNsPerSec + 103 * kNsPerMs), out);
  EXPECT_EQ(out.lost_before, 0u);
}

TEST(VelodyneDecoder, MaxPointsPerScanBoundsADualReturnSweepAt300Rpm) {
  // Dual-return packets every 663.552 µs, 384 points each, for 0.2 s.
  EXPECT_GE(decoder("VLP-16")->maxPointsPerScan(), std::size_t(0.2 / 663.552e-6 * 384));
  EXPECT_GE(decoder("HDL-32E")->maxPointsPerScan(), std::size_t(0.2 / 276.48e-6 * 384));
  EXPECT_EQ(decoder("VLP-16")->model(), "VLP-16");
  EXPECT_DOUBLE_EQ(decoder("VLP-32C")->scanRateHz(), 10.0);  // nothing seen yet
}

}  // namespace
}  // namespace rigcal::drivers
