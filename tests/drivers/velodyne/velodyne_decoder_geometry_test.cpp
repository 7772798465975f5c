// Velodyne decoder geometry: axes, azimuth correction and interpolation, the scan-cut azimuth, dual-return
// de-duplication and the range limits.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "packet_builder.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"
#include "velodyne_decoder_helpers.hpp"

namespace rigcal::drivers {
namespace {

using namespace test_velodyne;
using test::VelodynePacketBuilder;
using velodyne::Model;

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

}  // namespace
}  // namespace rigcal::drivers
