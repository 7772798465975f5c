#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "packet_builder.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

using test::VelodynePacketBuilder;
using velodyne::firingOffsetUs;
using velodyne::HourResolver;
using velodyne::Model;

constexpr TimeNs kHour = 3600 * kNsPerSec;
// 2024-04-19 02:00:00 UTC, a top of the hour.
constexpr TimeNs kHourStart = 1713492000 * kNsPerSec;

std::unique_ptr<PacketDecoder> decoder(const std::string& model, TimeSource source = TimeSource::kSensorClock,
                                       VelodyneOptions options = {}) {
  DecoderConfig config;
  config.model = model;
  config.time_source = source;
  config.min_range_m = 0.3f;
  config.max_range_m = 300.f;
  return makeVelodyneDecoder(config, options);
}

double azimuthDeg(const Point& p) {
  return std::fmod(std::atan2(-p.y, p.x) * 180.0 / std::numbers::pi + 360.0, 360.0);
}

void expectMalformed(PacketDecoder& d, const std::vector<std::uint8_t>& bytes, const std::string& field) {
  UdpPacket p;
  p.payload = bytes;
  DecodedPacket out;
  d.decode(p, out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed) << field;
  EXPECT_NE(out.error.find(field), std::string::npos) << out.error;
  EXPECT_EQ(out.error.find('\n'), std::string::npos) << out.error;
  EXPECT_TRUE(out.points.empty());
}

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

TEST(VelodyneDecoder, AxesFollowTheRosConvention) {
  auto d = decoder("VLP-16");
  // Laser 1 (+1°) at rotor azimuth 0° (forward) and 90° (to the right).
  VelodynePacketBuilder b(0x22, 0x37, 1000);
  b.setAzimuth(0, 0).setReturn(0, 1, 5000, 7);  // 10 m
  for (int k = 1; k < 12; ++k) b.setAzimuth(k, 9000);
  b.setReturn(1, 1, 5000, 9);
  DecodedPacket out;
  d->decode(b.packet(kHourStart), out);
  ASSERT_EQ(out.points.size(), 2u);
  const double c1 = std::cos(std::numbers::pi / 180);
  EXPECT_NEAR(out.points[0].x, 10 * c1, 1e-4);
  EXPECT_NEAR(out.points[0].y, 0, 1e-4);
  EXPECT_NEAR(out.points[0].z, 10 * std::sin(std::numbers::pi / 180), 1e-4);
  EXPECT_NEAR(out.points[1].x, 0, 1e-4);
  EXPECT_NEAR(out.points[1].y, -10 * c1, 1e-4);  // clockwise rotor: 90° is on the right, y < 0
  EXPECT_EQ(out.points[0].ring, 1);
  EXPECT_EQ(out.points[1].intensity, 9);
}

TEST(VelodyneDecoder, AzimuthCorrectionIsSubtracted) {
  auto d = decoder("VLP-32C");  // nominal table: laser 0 sits 1.4° clockwise of the rotor angle
  VelodynePacketBuilder b(0x28, 0x37, 1000);
  b.rampAzimuth(1000, 20).setReturn(0, 0, 2500, 1);  // 10 m
  DecodedPacket out;
  d->decode(b.packet(kHourStart), out);
  ASSERT_EQ(out.points.size(), 1u);
  EXPECT_NEAR(azimuthDeg(out.points[0]), 10.0 + 1.4, 1e-3);
  EXPECT_NEAR(std::atan2(out.points[0].z, std::hypot(out.points[0].x, out.points[0].y)) * 180 / std::numbers::pi,
              -25.0, 1e-4);
}

TEST(VelodyneDecoder, AzimuthIsInterpolatedByFiringTime) {
  auto d = decoder("VLP-16");
  VelodynePacketBuilder b(0x22, 0x37, 1000);
  b.rampAzimuth(35800, 40).fill(5000);  // crosses 0° at block 5
  DecodedPacket out;
  d->decode(b.packet(kHourStart), out);
  ASSERT_EQ(out.points.size(), 384u);
  for (int blk = 0; blk < 12; ++blk)
    for (int c = 0; c < 32; ++c) {
      const Point& p = out.points[blk * 32 + c];
      const double expected = std::fmod(
          (35800 + 40 * blk + std::floor(40 * velodyne::azimuthFraction(Model::kVlp16, 0, c) + 0.5)) / 100.0, 360.0);
      double diff = std::abs(azimuthDeg(p) - expected);
      diff = std::min(diff, 360 - diff);
      EXPECT_LT(diff, 2e-4) << blk << ' ' << c;
      // The cut azimuth is the block's.
      EXPECT_FLOAT_EQ(out.azimuth_deg[blk * 32 + c], static_cast<float>(((35800 + 40 * blk) % 36000) / 100.0));
    }
}

TEST(VelodyneDecoder, PacketCutReportsTheFirstBlockAzimuth) {
  VelodyneOptions options;
  options.cut = VelodyneOptions::Cut::kPacket;
  auto d = decoder("VLP-16", TimeSource::kSensorClock, options);
  VelodynePacketBuilder b(0x22, 0x37, 1000);
  b.rampAzimuth(35800, 40).fill(5000);
  DecodedPacket out;
  d->decode(b.packet(kHourStart), out);
  ASSERT_FALSE(out.points.empty());
  for (float a : out.azimuth_deg) EXPECT_FLOAT_EQ(a, 358.0f);
}

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
    EXPECT_EQ(out.packet_time_ns, t0);
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

TEST(VelodyneDecoder, DualReturnDropsASecondReturnIdenticalToTheFirst) {
  auto d = decoder("VLP-16");
  VelodynePacketBuilder b(0x22, 0x39, 1000);
  b.rampAzimuth(0, 40, 2);
  b.setReturn(0, 3, 3000, 20).setReturn(1, 3, 3000, 20);  // identical: one point
  b.setReturn(0, 4, 3000, 20).setReturn(1, 4, 3100, 8);   // distinct: two points
  b.setReturn(0, 5, 0, 0).setReturn(1, 5, 3000, 8);       // no first return: the second stays
  DecodedPacket out;
  d->decode(b.packet(kHourStart), out);
  ASSERT_EQ(out.points.size(), 4u);
  EXPECT_EQ(out.points[0].ring, 3);
  EXPECT_EQ(out.points[0].return_index, 0);
  EXPECT_EQ(out.points[1].ring, 4);
  EXPECT_EQ(out.points[2].ring, 4);
  EXPECT_EQ(out.points[2].return_index, 1);
  EXPECT_EQ(out.points[3].ring, 5);
  EXPECT_EQ(out.points[3].return_index, 1);
  // Both returns of a pair fired at the same instant.
  EXPECT_EQ(out.points[1].time_ns, out.points[2].time_ns);
}

TEST(VelodyneDecoder, RangeLimitsCompareTheFloatDistance) {
  // Distances are float (count × unit) compared against the limit as written (0.3, not 0.3f), as
  // nebula does: 149 counts (0.298 m) are out, 150 counts (0.3000000119 m in float) are in.
  auto d = decoder("VLP-16");  // 0.3 m .. 300 m, 2 mm units
  VelodynePacketBuilder b(0x22, 0x37, 1000);
  b.rampAzimuth(0, 40).setReturn(0, 0, 149, 1).setReturn(0, 1, 150, 1).setReturn(0, 2, 65535, 1);
  b.setReturn(0, 3, 49999, 1).setReturn(0, 4, 50000, 1);
  DecodedPacket out;
  d->decode(b.packet(kHourStart), out);
  ASSERT_EQ(out.points.size(), 4u);
  EXPECT_EQ(out.points[0].ring, 1);
  EXPECT_EQ(out.points[1].ring, 2);  // 131.07 m, the longest a 2 mm count can say
  DecoderConfig config;
  config.model = "VLP-16";
  config.min_range_m = 1.0f;
  config.max_range_m = 100.0f;
  makeVelodyneDecoder(config)->decode(b.packet(kHourStart), out);
  ASSERT_EQ(out.points.size(), 1u);  // 99.998 m in, 100.000 m out
  EXPECT_EQ(out.points[0].ring, 3);
  config.min_range_m = 5.0f;
  config.max_range_m = 1.0f;
  EXPECT_THROW(makeVelodyneDecoder(config), std::runtime_error);
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
