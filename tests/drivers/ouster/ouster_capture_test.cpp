// The Ouster decoder against real captures and ouster-sdk's own decodes of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "md5.hpp"
#include "rigcal/drivers/ouster/ouster_decoder.hpp"
#include "rigcal/drivers/ouster/ouster_raw_scan.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"
#include "test_data.hpp"

namespace rigcal::drivers::ouster {
namespace {

struct Captured {
  std::vector<std::uint8_t> bytes;
  TimeNs receive_ns = 0;
  std::uint32_t source = 0;
  UdpPacket view() const {
    UdpPacket p;
    p.payload = bytes;
    p.receive_ns = receive_ns;
    p.source.address = source;
    return p;
  }
};

std::vector<Captured> readCapture(const std::filesystem::path& pcap, PacketFilter filter = {}) {
  std::vector<Captured> out;
  PcapSource source(pcap, filter);
  while (auto p = source.next())
    out.push_back(Captured{{p->payload.begin(), p->payload.end()}, p->receive_ns, p->source.address});
  return out;
}

template <class T>
std::string md5Of(const std::vector<T>& v) {
  return test::md5Hex(v.data(), v.size() * sizeof(T));
}

struct DecodedCapture {
  std::vector<Scan> scans;
  AssemblerStats stats;
  std::size_t data = 0, ignored = 0, malformed = 0;
  std::string last_error;
};

DecodedCapture decodeAll(PacketDecoder& decoder, const std::vector<Captured>& packets) {
  DecodedCapture d;
  ScanAssembler assembler("os", AssemblerConfig{}, [&](Scan&& s) { d.scans.push_back(std::move(s)); });
  DecodedPacket out;
  for (const auto& c : packets) {
    decoder.decode(c.view(), out);
    if (out.kind == DecodedPacket::Kind::kData) ++d.data;
    if (out.kind == DecodedPacket::Kind::kIgnored) ++d.ignored;
    if (out.kind == DecodedPacket::Kind::kMalformed) {
      ++d.malformed;
      d.last_error = out.error;
    }
    if (out.kind == DecodedPacket::Kind::kData) {
      EXPECT_EQ(out.points.size(), out.azimuth_deg.size());
      EXPECT_TRUE(out.frame_id.has_value());
    }
    assembler.add(out);
  }
  assembler.flush();
  d.stats = assembler.stats();
  return d;
}

std::unique_ptr<PacketDecoder> decoderFor(const std::filesystem::path& metadata, const std::string& model = "Ouster") {
  DecoderConfig config;
  config.model = model;
  config.metadata = metadata;
  return makeOusterDecoder(config);
}

// ---- md5 of every field against ouster-sdk's LidarScan -------------------------------------------------

class OusterDigest : public testing::TestWithParam<const char*> {};

TEST_P(OusterDigest, RawFieldsMatchOusterSdkExactly) {
  const std::string base = std::string("ouster/") + GetParam() + "_1024x10";
  RIGCAL_REQUIRE_DATA(pcap, base + ".pcap");
  const auto dir = pcap.parent_path();
  const Metadata md = parseMetadataFile(dir / (std::string(GetParam()) + "_1024x10.json"));
  std::ifstream digest_file(dir / (std::string(GetParam()) + "_1024x10_digest.json"));
  const auto digest = nlohmann::json::parse(digest_file)["scans"][0];

  RawScan scan(md);
  std::size_t lidar = 0;
  for (const auto& c : readCapture(pcap, PacketFilter{7502, std::nullopt})) {
    if (c.bytes.size() == kImuPacketSize) continue;
    ASSERT_EQ(scan.add(c.bytes), RawScan::AddResult::kAdded) << scan.error();
    ++lidar;
  }
  EXPECT_EQ(lidar, 64u);
  ASSERT_TRUE(scan.frameId().has_value());
  EXPECT_EQ(std::to_string(*scan.frameId()), digest["FRAME_ID"].get<std::string>());

  const std::map<std::string, std::string> ours = {
      {"RANGE", md5Of(scan.range)},          {"RANGE2", md5Of(scan.range2)},
      {"REFLECTIVITY", md5Of(scan.reflectivity)}, {"REFLECTIVITY2", md5Of(scan.reflectivity2)},
      {"SIGNAL", md5Of(scan.signal)},        {"SIGNAL2", md5Of(scan.signal2)},
      {"NEAR_IR", md5Of(scan.near_ir)},      {"TIMESTAMP", md5Of(scan.timestamp)},
      {"STATUS", md5Of(scan.status)},        {"MEASUREMENT_ID", md5Of(scan.measurement_id)},
  };
  std::size_t compared = 0;
  for (const auto& [field, hash] : ours) {
    if (!digest.contains(field)) continue;
    EXPECT_EQ(hash, digest[field].get<std::string>()) << field;
    ++compared;
  }
  const bool low_rate = md.profile == UdpProfile::kRng15Rfl8Nir8;
  EXPECT_GE(compared, low_rate ? 6u : 7u);  // every field the digest holds except ENCODER_COUNT
}

INSTANTIATE_TEST_SUITE_P(Captures, OusterDigest,
                         testing::Values("OS-2-32-U0_v2.0.0", "OS-1-32-G_v2.1.1", "OS-2-128-U1_v2.3.0",
                                         "OS-0-32-U1_v2.2.0", "OS-0-128-U1_v2.3.0"),
                         [](const testing::TestParamInfo<const char*>& param) {
                           std::string name = param.param;
                           std::replace_if(name.begin(), name.end(), [](char c) { return !std::isalnum(c); }, '_');
                           return name;
                         });

// The decoder's points are the raw scan's non-zero ranges, one for one, at the right place.
TEST(OusterCapture, DecodedPointsAreTheRawScansReturns) {
  RIGCAL_REQUIRE_DATA(dir, "ouster");
  for (const char* name : {"OS-2-32-U0_v2.0.0", "OS-2-128-U1_v2.3.0", "OS-0-32-U1_v2.2.0", "OS-0-128-U1_v2.3.0"}) {
    SCOPED_TRACE(name);
    const auto meta = dir / (std::string(name) + "_1024x10.json");
    const auto packets = readCapture(dir / (std::string(name) + "_1024x10.pcap"), PacketFilter{7502, std::nullopt});
    const Metadata md = parseMetadataFile(meta);
    RawScan raw(md);
    for (const auto& c : packets)
      if (c.bytes.size() != kImuPacketSize) raw.add(c.bytes);
    DecoderConfig config;
    config.model = "Ouster";
    config.metadata = meta;
    config.min_range_m = 0.0f;
    config.max_range_m = 1000.0f;
    OusterDecoder decoder(config, md);
    const DecodedCapture d = decodeAll(decoder, packets);
    ASSERT_EQ(d.scans.size(), 1u);
    EXPECT_EQ(d.malformed, 0u);
    EXPECT_EQ(d.stats.lost_packets, 0u);
    std::vector<double> raw_m;
    for (std::size_t i = 0; i < raw.range.size(); ++i) {
      const std::size_t col = i % std::size_t(md.columns_per_frame);
      if (!PacketFormat::statusValid(std::uint32_t(raw.status[col]))) continue;
      if (raw.range[i] != 0) raw_m.push_back(raw.range[i] * 1e-3);
      if (raw.range2[i] != 0) raw_m.push_back(raw.range2[i] * 1e-3);
    }
    const Scan& scan = d.scans[0];
    ASSERT_EQ(scan.size(), raw_m.size());
    // A return lies on its beam, (r − n) from the beam origin, which is b from the lidar origin: its
    // distance to the lidar origin is within [r − 2b, r]. Sorted, the two lists pair up the same way.
    const double tx = md.lidar_to_sensor[3] * 1e-3, ty = md.lidar_to_sensor[7] * 1e-3, tz = md.lidar_to_sensor[11] * 1e-3;
    std::vector<double> ours;
    for (std::size_t i = 0; i < scan.size(); ++i)
      ours.push_back(std::hypot(scan.x[i] - tx, scan.y[i] - ty, scan.z[i] - tz));
    std::sort(ours.begin(), ours.end());
    std::sort(raw_m.begin(), raw_m.end());
    const double b = md.beam_to_lidar[3] * 1e-3;
    double worst = 0;
    for (std::size_t i = 0; i < ours.size(); ++i) worst = std::max(worst, std::abs(ours[i] - (raw_m[i] - b)));
    EXPECT_LE(worst, b + 2e-3) << "b = " << b;
  }
}

TEST(OusterCapture, XyzIsPlausibleOnARealCapture) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/OS-2-128-U1_v2.3.0_1024x10.pcap");
  auto decoder = decoderFor(pcap.parent_path() / "OS-2-128-U1_v2.3.0_1024x10.json", "OS2-128");
  const DecodedCapture d = decodeAll(*decoder, readCapture(pcap, PacketFilter{7502, std::nullopt}));
  ASSERT_EQ(d.scans.size(), 1u);
  const Scan& s = d.scans[0];
  ASSERT_GT(s.size(), 50'000u);
  std::vector<float> ranges;
  float zmin = 1e9f, zmax = -1e9f;
  std::set<int> quadrants;
  for (std::size_t i = 0; i < s.size(); ++i) {
    ASSERT_TRUE(std::isfinite(s.x[i]) && std::isfinite(s.y[i]) && std::isfinite(s.z[i]));
    const float r = std::sqrt(s.x[i] * s.x[i] + s.y[i] * s.y[i] + s.z[i] * s.z[i]);
    ranges.push_back(r);
    zmin = std::min(zmin, s.z[i]);
    zmax = std::max(zmax, s.z[i]);
    quadrants.insert(int(s.x[i] > 0) * 2 + int(s.y[i] > 0));
    EXPECT_LT(s.ring[i], 128);
    EXPECT_LT(s.offset_ns[i], 110'000'000u);  // one 10 Hz sweep
  }
  std::nth_element(ranges.begin(), ranges.begin() + long(ranges.size() / 2), ranges.end());
  const float median = ranges[ranges.size() / 2];
  EXPECT_GT(median, 1.0f);
  EXPECT_LT(median, 150.0f);
  EXPECT_EQ(quadrants.size(), 4u);  // a full turn
  // OS2 altitudes span about ±11°: nothing far above or below the sensor near the sensor.
  EXPECT_GT(*std::min_element(ranges.begin(), ranges.end()), 0.29f);
  EXPECT_LT(zmax - zmin, 2.0f * 0.2f * *std::max_element(ranges.begin(), ranges.end()) + 1.0f);
}

// ---- the LEGACY OS1-64 capture of exactly one frame ------------------------------------------------------

TEST(OusterCapture, Legacy64BeamCaptureIsOneFullScan) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/OS-1-64_1024x10_fw20.pcap");
  const auto meta = pcap.parent_path() / "OS-1-64_sensor_config_reduced.json";
  auto decoder = decoderFor(meta, "OS1-64");
  const auto packets = readCapture(pcap);
  const DecodedCapture d = decodeAll(*decoder, packets);
  EXPECT_EQ(d.data, 64u);
  EXPECT_EQ(d.ignored, 11u);  // IMU packets
  EXPECT_EQ(d.malformed, 0u) << d.last_error;
  ASSERT_EQ(d.scans.size(), 1u);
  EXPECT_EQ(d.stats.lost_packets, 0u);
  const Scan& s = d.scans[0];
  std::set<std::uint16_t> rings(s.ring.begin(), s.ring.end());
  EXPECT_EQ(rings.size(), 64u);
  EXPECT_EQ(*rings.rbegin(), 63);
  // Points of the whole turn, spread over ~100 ms of sensor time.
  const auto span = *std::max_element(s.offset_ns.begin(), s.offset_ns.end());
  EXPECT_GT(span, 90'000'000u);
  EXPECT_LT(span, 101'000'000u);
  RawScan raw(parseMetadataFile(meta));
  for (const auto& c : packets)
    if (c.bytes.size() != kImuPacketSize) {
      ASSERT_EQ(raw.add(c.bytes), RawScan::AddResult::kAdded);
    }
  std::size_t in_range = 0;
  for (std::uint32_t r : raw.range) in_range += (r >= 300 && r <= 300'000);
  EXPECT_EQ(s.size(), in_range);
  EXPECT_GT(s.size(), 15'000u);  // 16749 returns in range in this capture
}

// ---- two sensors on one port ---------------------------------------------------------------------------

TEST(OusterCapture, TwoSensorsOnOnePortDecodeWithTheirOwnMetadata) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/same_ports.pcap");
  const auto dir = pcap.parent_path();
  std::set<std::uint32_t> sources;
  for (const auto& c : readCapture(pcap)) sources.insert(c.source);
  ASSERT_EQ(sources.size(), 2u);
  const std::filesystem::path metas[2] = {dir / "same_ports.1.json", dir / "same_ports.2.json"};
  std::set<int> matched;
  for (std::uint32_t src : sources) {
    const auto packets = readCapture(pcap, PacketFilter{7502, src});
    int fits = -1;
    for (int k = 0; k < 2; ++k) {
      auto decoder = decoderFor(metas[k]);
      const DecodedCapture d = decodeAll(*decoder, packets);
      EXPECT_EQ(d.ignored, 1u);  // the IMU packet on the same port
      if (d.malformed == 0) {
        EXPECT_EQ(d.data, 1u);
        ASSERT_EQ(d.scans.size(), 1u);
        EXPECT_GT(d.scans[0].size(), 100u);
        fits = k;
      } else {
        EXPECT_EQ(d.malformed, 1u);
        EXPECT_NE(d.last_error.find("size"), std::string::npos) << d.last_error;
      }
    }
    ASSERT_GE(fits, 0) << formatIpv4(src);
    matched.insert(fits);
  }
  EXPECT_EQ(matched.size(), 2u);  // each sensor has its own metadata
}

// ---- edge cases ----------------------------------------------------------------------------------------

TEST(OusterCapture, CrcFooterIsCheckedOnFirmware3) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/crc_test.pcap");
  auto decoder = decoderFor(pcap.parent_path() / "crc_test.json", "OS0-128");
  auto packets = readCapture(pcap);
  const DecodedCapture d = decodeAll(*decoder, packets);
  EXPECT_EQ(d.data, 34u);
  EXPECT_EQ(d.ignored, 10u);
  EXPECT_EQ(d.malformed, 0u) << d.last_error;
  ASSERT_EQ(d.scans.size(), 2u);  // frame 254 complete (32 packets of 16 of 512 columns), then 2 packets of 255
  EXPECT_EQ(d.stats.lost_packets, 0u);

  auto fresh = decoderFor(pcap.parent_path() / "crc_test.json", "OS0-128");
  Captured corrupt = *std::find_if(packets.begin(), packets.end(), [](const Captured& c) { return c.bytes.size() > 48; });
  corrupt.bytes[100] ^= 0x01;
  DecodedPacket out;
  fresh->decode(corrupt.view(), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed);
  EXPECT_NE(out.error.find("crc64"), std::string::npos) << out.error;
}

TEST(OusterCapture, EmptyCaptureDecodesToNothing) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/empty_pcap.pcap");
  auto decoder = decoderFor(pcap.parent_path() / "OS-1-32-G_v2.1.1_1024x10.json");
  const DecodedCapture d = decodeAll(*decoder, readCapture(pcap));
  EXPECT_EQ(d.data + d.ignored + d.malformed, 0u);
  EXPECT_TRUE(d.scans.empty());
}

TEST(OusterCapture, ForeignPacketIsRejectedNamingItsSize) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/VLI-16-one-packet.pcap");
  auto decoder = decoderFor(pcap.parent_path() / "OS-1-32-G_v2.1.1_1024x10.json");
  const auto packets = readCapture(pcap);
  ASSERT_EQ(packets.size(), 1u);
  DecodedPacket out;
  decoder->decode(packets[0].view(), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed);
  EXPECT_EQ(out.error, "Ouster LEGACY packet: size 1212, expected 6464");
  EXPECT_TRUE(out.points.empty());
}

}  // namespace
}  // namespace rigcal::drivers::ouster
