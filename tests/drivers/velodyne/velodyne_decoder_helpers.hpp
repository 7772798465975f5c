#pragma once
// What the Velodyne decoder tests share: a decoder as the rig configures one, a point's azimuth, and the
// check that a bad packet is rejected naming its field.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"

namespace rigcal::drivers::test_velodyne {

constexpr TimeNs kHour = 3600 * kNsPerSec;
// 2024-04-19 02:00:00 UTC, a top of the hour.
constexpr TimeNs kHourStart = 1713492000 * kNsPerSec;

/// A decoder as a rig configures one (nominal calibration table, 0.3–300 m).
inline std::unique_ptr<PacketDecoder> decoder(const std::string& model, TimeSource source = TimeSource::kSensorClock,
                                              VelodyneOptions options = {}) {
  DecoderConfig config;
  config.model = model;
  config.time_source = source;
  config.min_range_m = 0.3f;
  config.max_range_m = 300.f;
  return makeVelodyneDecoder(config, options);
}

/// A point's azimuth in Velodyne's convention (clockwise from forward), degrees in [0, 360).
inline double azimuthDeg(const Point& p) {
  return std::fmod(std::atan2(-p.y, p.x) * 180.0 / std::numbers::pi + 360.0, 360.0);
}

/// `bytes` is rejected as malformed, with a one-line error naming `field`, and gives no points.
inline void expectMalformed(PacketDecoder& d, const std::vector<std::uint8_t>& bytes, const std::string& field) {
  UdpPacket p;
  p.payload = bytes;
  DecodedPacket out;
  d.decode(p, out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed) << field;
  EXPECT_NE(out.error.find(field), std::string::npos) << out.error;
  EXPECT_EQ(out.error.find('\n'), std::string::npos) << out.error;
  EXPECT_TRUE(out.points.empty());
}

}  // namespace rigcal::drivers::test_velodyne
