// The Ouster decoder on synthetic packets: geometry, axes, dual returns, timing, loss, validation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "rigcal/drivers/ouster/ouster_decoder.hpp"
#include "rigcal/drivers/ouster/ouster_raw_scan.hpp"

namespace rigcal::drivers::ouster {
namespace {

// Two beams: beam 0 at azimuth 0 / altitude 0, beam 1 at altitude 30°, 1024 columns, 16 per packet.
Metadata syntheticMetadata(const std::string& profile, const std::string& extra = "") {
  const std::string text = R"({
    "beam_altitude_angles": [0, 30], "beam_azimuth_angles": [0, 0],
    "lidar_mode": "1024x10", "prod_line": "OS-1-64", "initialization_id": 4242, "prod_sn": "992210000957",
    "lidar_origin_to_beam_origin_mm": 15.806,
    "data_format": {"pixels_per_column": 2, "columns_per_packet": 16, "columns_per_frame": 1024,
                    "pixel_shift_by_row": [0, 0], "column_window": [0, 1023],
                    "udp_profile_lidar": ")" + profile + R"("})" + extra + "}";
  return parseMetadata(text, "synthetic.json");
}

DecoderConfig config(TimeSource ts = TimeSource::kSensorClock) {
  DecoderConfig c;
  c.model = "OS1-64";
  c.time_source = ts;
  return c;
}

void put16(std::vector<std::uint8_t>& b, std::size_t at, std::uint16_t v) { std::memcpy(&b[at], &v, 2); }
void put32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) { std::memcpy(&b[at], &v, 4); }
void put64(std::vector<std::uint8_t>& b, std::size_t at, std::uint64_t v) { std::memcpy(&b[at], &v, 8); }

// A packet whose columns have measurement ids first_mid.., timestamps t0 + 97656·i, every range = range_mm
// (second return 2·range_mm in dual profiles), reflectivity = 10 + beam.
std::vector<std::uint8_t> makePacket(const Metadata& md, std::uint32_t frame_id, int first_mid, std::uint32_t range_mm,
                                     std::uint64_t t0 = 1'000'000'000, bool valid = true) {
  const PacketFormat f(md.profile, md.pixels_per_column, md.columns_per_packet);
  std::vector<std::uint8_t> b(f.packet_size, 0);
  if (!f.legacy()) {
    put16(b, 0, 1);
    put16(b, 2, std::uint16_t(frame_id));
    put32(b, 4, md.init_id);  // low 24 bits, then the serial's first byte overwrites byte 7
    put64(b, 7, md.serial);
  }
  for (int c = 0; c < f.columns_per_packet; ++c) {
    const std::size_t col = f.packet_header_size + std::size_t(c) * f.column_size;
    put64(b, col, t0 + std::uint64_t(c) * 97'656);
    put16(b, col + 8, std::uint16_t(first_mid + c));
    if (f.legacy()) {
      put16(b, col + 10, std::uint16_t(frame_id));
      put32(b, col + f.column_size - 4, valid ? 0xffffffffu : 0u);
    } else {
      put16(b, col + 10, valid ? 1 : 0);
    }
    for (int u = 0; u < f.pixels_per_column; ++u) {
      const std::size_t px = col + f.column_header_size + std::size_t(u) * f.pixel_size;
      switch (f.profile) {
        case UdpProfile::kLegacy:
        case UdpProfile::kRng19Rfl8Sig16Nir16:
          put32(b, px, range_mm);
          b[px + 4] = std::uint8_t(10 + u);
          break;
        case UdpProfile::kRng19Rfl8Sig16Nir16Dual:
          put32(b, px, range_mm);
          b[px + 3] = std::uint8_t(10 + u);
          put32(b, px + 4, 2 * range_mm);
          b[px + 7] = std::uint8_t(20 + u);
          break;
        case UdpProfile::kRng15Rfl8Nir8:
          put16(b, px, std::uint16_t(range_mm / 8));
          b[px + 2] = std::uint8_t(10 + u);
          break;
        default: break;
      }
    }
  }
  return b;
}

UdpPacket view(const std::vector<std::uint8_t>& bytes, TimeNs receive_ns = 5'000'000'000) {
  UdpPacket p;
  p.payload = bytes;
  p.receive_ns = receive_ns;
  return p;
}

TEST(OusterDecoder, AxesMatchOursAndTheSensorFrame) {
  const Metadata md = syntheticMetadata("LEGACY");
  OusterDecoder decoder(config(), md);
  DecodedPacket out;
  // Column W/2 of beam 0 (azimuth 0, altitude 0): straight ahead, +x, at the lidar origin's height.
  const auto ahead = makePacket(md, 7, 512, 10'000);
  decoder.decode(view(ahead), out);
  ASSERT_EQ(out.kind, DecodedPacket::Kind::kData) << out.error;
  ASSERT_EQ(out.points.size(), 32u);
  const Point& p = out.points[0];
  EXPECT_EQ(p.ring, 0);
  EXPECT_NEAR(p.x, 10.0, 1e-5);
  EXPECT_NEAR(p.y, 0.0, 1e-5);
  EXPECT_NEAR(p.z, 0.03618, 1e-6);  // lidar_to_sensor z offset
  EXPECT_NEAR(out.azimuth_deg[0], 0.0, 1e-3);
  EXPECT_FLOAT_EQ(p.intensity, 10.0f);
  EXPECT_EQ(*out.frame_id, 7u);
  // Beam 1 at 30° altitude: up, the beam origin 15.806 mm off the axis.
  const Point& q = out.points[1];
  EXPECT_EQ(q.ring, 1);
  const double b = 0.015806, r = 10.0;
  EXPECT_NEAR(q.x, b + (r - b) * std::cos(M_PI / 6), 1e-5);
  EXPECT_NEAR(q.z, 0.03618 + (r - b) * std::sin(M_PI / 6), 1e-5);
  EXPECT_FLOAT_EQ(q.intensity, 11.0f);

  // Column 0 fires behind (−x, the connector side), column W/4 to the left (+y): clockwise from above.
  decoder.decode(view(makePacket(md, 7, 0, 10'000)), out);
  EXPECT_NEAR(out.points[0].x, -10.0, 1e-5);
  EXPECT_NEAR(out.points[0].y, 0.0, 1e-5);
  EXPECT_NEAR(out.azimuth_deg[0], 180.0, 1e-3);
  decoder.decode(view(makePacket(md, 7, 256, 10'000)), out);
  EXPECT_NEAR(out.points[0].x, 0.0, 1e-5);
  EXPECT_NEAR(out.points[0].y, 10.0, 1e-5);
  EXPECT_NEAR(out.azimuth_deg[0], 90.0, 1e-3);
  // The next column (one 1024th of a turn later) is a little to the right of that.
  EXPECT_NEAR(out.azimuth_deg[2], 90.0 - 360.0 / 1024.0, 1e-3);
}

TEST(OusterDecoder, DualReturnsAndLowRateRangeUnit) {
  {
    const Metadata md = syntheticMetadata("RNG19_RFL8_SIG16_NIR16_DUAL");
    OusterDecoder decoder(config(), md);
    DecodedPacket out;
    decoder.decode(view(makePacket(md, 1, 512, 5'000)), out);
    ASSERT_EQ(out.kind, DecodedPacket::Kind::kData) << out.error;
    ASSERT_EQ(out.points.size(), 64u);  // 16 columns × 2 beams × 2 returns
    EXPECT_EQ(out.points[0].return_index, 0);
    EXPECT_EQ(out.points[1].return_index, 1);
    EXPECT_NEAR(out.points[0].x, 5.0, 1e-5);
    EXPECT_NEAR(out.points[1].x, 10.0, 1e-5);
    EXPECT_FLOAT_EQ(out.points[1].intensity, 20.0f);
  }
  {
    const Metadata md = syntheticMetadata("RNG15_RFL8_NIR8");
    OusterDecoder decoder(config(), md);
    DecodedPacket out;
    decoder.decode(view(makePacket(md, 1, 512, 8 * 1250)), out);
    ASSERT_EQ(out.kind, DecodedPacket::Kind::kData) << out.error;
    EXPECT_NEAR(out.points[0].x, 10.0, 1e-5);  // 1250 units of 8 mm
    RawScan raw(md);
    ASSERT_EQ(raw.add(makePacket(md, 1, 512, 8 * 1250)), RawScan::AddResult::kAdded);
    EXPECT_EQ(raw.range[512], 10'000u);
    EXPECT_EQ(raw.reflectivity[1024 + 512], 11u);
  }
}

TEST(OusterDecoder, RangeFilterAndInvalidColumns) {
  const Metadata md = syntheticMetadata("RNG19_RFL8_SIG16_NIR16");
  DecoderConfig c = config();
  c.min_range_m = 1.0f;
  c.max_range_m = 20.0f;
  OusterDecoder decoder(c, md);
  DecodedPacket out;
  decoder.decode(view(makePacket(md, 1, 0, 0)), out);  // no return anywhere
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kData);
  EXPECT_TRUE(out.points.empty());
  decoder.decode(view(makePacket(md, 1, 16, 999)), out);
  EXPECT_TRUE(out.points.empty());
  decoder.decode(view(makePacket(md, 1, 32, 20'001)), out);
  EXPECT_TRUE(out.points.empty());
  decoder.decode(view(makePacket(md, 1, 48, 20'000)), out);
  EXPECT_EQ(out.points.size(), 32u);
  decoder.decode(view(makePacket(md, 1, 64, 5'000, 1, /*valid=*/false)), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kIgnored);  // every column outside the window
  EXPECT_TRUE(out.points.empty());
}

TEST(OusterDecoder, SensorAndHostTime) {
  const Metadata md = syntheticMetadata("RNG19_RFL8_SIG16_NIR16");
  DecodedPacket out;
  OusterDecoder sensor(config(TimeSource::kSensorClock), md);
  sensor.decode(view(makePacket(md, 1, 0, 5'000, 1'000'000'000)), out);
  EXPECT_EQ(out.packet_time_ns, 1'000'000'000);
  EXPECT_EQ(out.points.back().time_ns, 1'000'000'000 + 15 * 97'656);
  OusterDecoder host(config(TimeSource::kHostReceive), md);
  host.decode(view(makePacket(md, 1, 0, 5'000, 1'000'000'000), 7'000'000'000), out);
  EXPECT_EQ(out.points.back().time_ns, 7'000'000'000);  // the last column arrives last
  EXPECT_EQ(out.packet_time_ns, 7'000'000'000 - 15 * 97'656);
}

TEST(OusterDecoder, CountsLostPacketsAcrossFramesAndWraps) {
  const Metadata md = syntheticMetadata("RNG19_RFL8_SIG16_NIR16");
  OusterDecoder decoder(config(), md);
  DecodedPacket out;
  auto feed = [&](std::uint32_t frame, int mid) {
    decoder.decode(view(makePacket(md, frame, mid, 5'000)), out);
    EXPECT_EQ(out.kind, DecodedPacket::Kind::kData) << out.error;
    return out.lost_before;
  };
  EXPECT_EQ(feed(65534, 0), 0u);
  const std::uint64_t k0 = out.order_key;
  EXPECT_EQ(feed(65534, 16), 0u);
  EXPECT_EQ(feed(65534, 64), 2u);       // 32 and 48 missing
  EXPECT_EQ(feed(65535, 16), 59u + 1);  // slots 5..63 (columns 80..1023) of 65534 and slot 0 of 65535
  EXPECT_EQ(feed(0, 0), 62u);           // frame id wraps: the rest of 65535
  EXPECT_GT(out.order_key, k0);
  EXPECT_EQ(*out.frame_id, 0u);
  EXPECT_EQ(feed(0, 0), 0u);            // a duplicate
  EXPECT_EQ(feed(65535, 1008), 0u);     // a late packet of the previous frame
  EXPECT_EQ(feed(0, 16), 0u);
  EXPECT_EQ(feed(30000, 0), 0u);        // the sensor restarted: not loss
}

TEST(OusterDecoder, LossOnlyCountsPacketsInTheColumnWindow) {
  Metadata md = syntheticMetadata("RNG19_RFL8_SIG16_NIR16");
  md.column_window_first = 900;
  md.column_window_last = 100;  // wraps through 0: slots 56..63 and 0..6
  OusterDecoder decoder(config(), md);
  DecodedPacket out;
  decoder.decode(view(makePacket(md, 3, 96, 5'000)), out);  // slot 6, last of the window's start
  decoder.decode(view(makePacket(md, 3, 912, 5'000)), out);  // slot 57: 56 was lost, 7..55 never sent
  EXPECT_EQ(out.lost_before, 1u);
  decoder.decode(view(makePacket(md, 4, 16, 5'000)), out);  // 58..63 and 0 lost
  EXPECT_EQ(out.lost_before, 7u);
}

TEST(OusterDecoder, ValidatesPacketsWithOneLineErrors) {
  const Metadata md = syntheticMetadata("RNG19_RFL8_SIG16_NIR16");
  OusterDecoder decoder(config(), md);
  DecodedPacket out;
  auto good = makePacket(md, 1, 0, 5'000);

  std::vector<std::uint8_t> imu(48, 0);
  decoder.decode(view(imu), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kIgnored);

  std::vector<std::uint8_t> short_packet(good.begin(), good.end() - 1);
  decoder.decode(view(short_packet), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed);
  EXPECT_EQ(out.error, "Ouster RNG19_RFL8_SIG16_NIR16 packet: size " + std::to_string(good.size() - 1) +
                           ", expected " + std::to_string(good.size()));

  auto bad = good;
  put16(bad, 0, 2);
  decoder.decode(view(bad), out);
  EXPECT_EQ(out.error, "Ouster packet: packet_type 2, expected 1 (lidar)");

  bad = good;
  put32(bad, 4, 77);
  bad[7] = std::uint8_t(md.serial);
  decoder.decode(view(bad), out);
  EXPECT_EQ(out.error, "Ouster packet: init_id 77 does not match the metadata's 4242");

  bad = good;
  put16(bad, 32 + 8, 1024);
  decoder.decode(view(bad), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed);
  EXPECT_NE(out.error.find("measurement_id 1024"), std::string::npos) << out.error;

  bad = good;
  put16(bad, 32 + 5 * (12 + 2 * 12) + 8, 5000);  // column 5
  decoder.decode(view(bad), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed);
  EXPECT_TRUE(out.points.empty());
  EXPECT_EQ(out.error.find('\n'), std::string::npos);

  decoder.decode(view(good), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kData);
}

TEST(OusterDecoder, FactoryChecksModelAndMetadata) {
  EXPECT_FALSE(ousterModels().empty());
  DecoderConfig c;
  c.model = "OS9-999";
  try {
    makeOusterDecoder(c);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("OS9-999"), std::string::npos);
  }
  c.model = "OS1-64";
  EXPECT_THROW(makeOusterDecoder(c), std::runtime_error);  // no metadata file
  c.metadata = "/nonexistent/os.json";
  try {
    makeOusterDecoder(c);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/os.json"), std::string::npos);
  }
  const Metadata md = syntheticMetadata("LEGACY");  // prod_line OS-1-64
  DecoderConfig wrong = config();
  wrong.model = "OS2-128";
  EXPECT_THROW(OusterDecoder(wrong, md), std::runtime_error);
  DecoderConfig generic = config();
  generic.model = "Ouster";
  OusterDecoder any(generic, md);
  EXPECT_EQ(any.model(), "OS1-64");
  EXPECT_EQ(any.maxPointsPerScan(), 2048u);
  EXPECT_DOUBLE_EQ(any.scanRateHz(), 10.0);
}

TEST(OusterRawScan, DestaggerShiftsEachRow) {
  Metadata md = syntheticMetadata("LEGACY");
  md.pixel_shift_by_row = {3, -2};
  RawScan raw(md);
  std::vector<int> image(2 * 1024, 0);
  image[0] = 1;         // row 0, column 0
  image[1024 + 1] = 2;  // row 1, column 1
  const auto d = raw.destagger(image);
  EXPECT_EQ(d[3], 1);
  EXPECT_EQ(d[1024 + 1023], 2);
}

}  // namespace
}  // namespace rigcal::drivers::ouster

namespace rigcal::drivers::ouster {
namespace {

TEST(OusterPacketFormat, Crc64IsTheXzVariant) {
  const std::string check = "123456789";
  EXPECT_EQ(crc64(reinterpret_cast<const std::uint8_t*>(check.data()), check.size()), 0x995DC9BBDF1939FAull);
  std::vector<std::uint8_t> long_input(1000);
  for (std::size_t i = 0; i < long_input.size(); ++i) long_input[i] = std::uint8_t(i * 7 + 3);
  // Slicing-by-8 and the byte-wise tail agree with each other on every split.
  const std::uint64_t whole = crc64(long_input.data(), long_input.size());
  EXPECT_NE(whole, crc64(long_input.data(), long_input.size() - 1));
  EXPECT_EQ(PacketFormat(UdpProfile::kRng15Rfl8Nir8, 128, 16).packet_size, 8448u);
  EXPECT_EQ(PacketFormat(UdpProfile::kLegacy, 64, 16).packet_size, 12608u);
  EXPECT_EQ(PacketFormat(UdpProfile::kFusaRng15Rfl8Nir8Dual, 128, 16).packet_size, 16640u);
  EXPECT_EQ(PacketFormat(UdpProfile::kRng19Rfl8Sig16Nir16Dual, 32, 16).packet_size, 8448u);
  EXPECT_THROW(PacketFormat(UdpProfile::kFiveWordPixel, 256, 64), std::invalid_argument);
}

}  // namespace
}  // namespace rigcal::drivers::ouster
