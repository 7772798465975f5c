// HesaiDecoder behaviour on real captures and on packets edited from them.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <set>

#include "hesai_test_util.hpp"
#include "rigcal/drivers/hesai/hesai_decoder.hpp"
#include "rigcal/drivers/hesai/hesai_firing_times.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

using hesai_test::Capture;
using hesai_test::loadCapture;

constexpr double kPi = 3.14159265358979323846;

DecoderConfig configFor(const std::string& model, const std::filesystem::path& calibration = {}) {
  DecoderConfig c;
  c.model = model;
  c.calibration = calibration;
  c.min_range_m = 0.05f;
  return c;
}

// Decodes one packet and flushes: all of that packet's points, whatever the azimuth ordering holds.
DecodedPacket decodeAlone(HesaiDecoder& decoder, const UdpPacket& packet) {
  DecodedPacket out, rest;
  decoder.decode(packet, out);
  decoder.flush(rest);
  out.points.insert(out.points.end(), rest.points.begin(), rest.points.end());
  out.azimuth_deg.insert(out.azimuth_deg.end(), rest.azimuth_deg.begin(), rest.azimuth_deg.end());
  return out;
}

TEST(HesaiDecoder, FactoryModelsAndErrors) {
  EXPECT_EQ(hesaiModels(), (std::vector<std::string>{"PandarXT16", "PandarXT32", "PandarQT128", "Pandar40P",
                                                     "Pandar64", "PandarQT64", "PandarXT32M"}));
  try {
    makeHesaiDecoder(configFor("PandarXT64"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown Hesai model 'PandarXT64'"), std::string::npos) << e.what();
  }
  try {
    makeHesaiDecoder(configFor("PandarQT128"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("PandarQT128: an angle-correction CSV is required"), std::string::npos);
  }
  RIGCAL_REQUIRE_DATA(xt16_csv, "hesai/PandarXT16.csv");
  try {
    makeHesaiDecoder(configFor("PandarXT32", xt16_csv));  // 16 rows for a 32-channel sensor
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("PandarXT16.csv:17: file ends after 16 channel rows, expected 32"),
              std::string::npos)
        << e.what();
  }
  auto d = makeHesaiDecoder(configFor("PandarXT32"));  // nominal angles
  EXPECT_EQ(d->model(), "PandarXT32");
  EXPECT_EQ(d->maxPointsPerScan(), 256'000u);
  EXPECT_EQ(d->scanRateHz(), 10.0);
}

TEST(HesaiDecoder, MalformedForeignAndEmptyPacketsDoNotDisturbDecoding) {
  RIGCAL_REQUIRE_DATA(path, "hesai/xt32_dual.pcap");
  const Capture capture = loadCapture(path);
  HesaiDecoder decoder(configFor("PandarXT32"));
  DecodedPacket out;
  decoder.decode(capture.packet(0), out);
  ASSERT_EQ(out.kind, DecodedPacket::Kind::kData);

  std::vector<std::vector<std::uint8_t>> bad = {
      {},                                                                            // empty payload
      std::vector<std::uint8_t>(capture.payloads[1].begin(), capture.payloads[1].begin() + 700),  // truncated
      std::vector<std::uint8_t>(1206, 0xFF),                                         // foreign (Velodyne size)
      {0xEE, 0xFF, 6, 1},                                                            // header cut short
  };
  for (const auto& payload : bad) {
    UdpPacket p;
    p.payload = payload;
    decoder.decode(p, out);
    EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed);
    EXPECT_FALSE(out.error.empty());
    EXPECT_EQ(out.error.find('\n'), std::string::npos);
    EXPECT_TRUE(out.points.empty());
  }
  decoder.decode(capture.packet(1), out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kData);
  EXPECT_EQ(out.lost_before, 0u);

  std::vector<std::uint8_t> gps(512, 0);
  gps[0] = 0xFF, gps[1] = 0xEE;
  UdpPacket p;
  p.payload = gps;
  decoder.decode(p, out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kIgnored);

  // A bad date is malformed under the sensor clock only.
  std::vector<std::uint8_t> bad_date = capture.payloads[2];
  bad_date[12 + 8 * 130 + 14] = 13;  // month 13
  p.payload = bad_date;
  decoder.decode(p, out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kMalformed);
  EXPECT_NE(out.error.find("date field 2019-13-25"), std::string::npos) << out.error;
  DecoderConfig host = configFor("PandarXT32");
  host.time_source = TimeSource::kHostReceive;
  HesaiDecoder host_decoder(host);
  host_decoder.decode(p, out);
  EXPECT_EQ(out.kind, DecodedPacket::Kind::kData);
}

TEST(HesaiDecoder, UdpSequenceGapsCountLostPackets) {
  RIGCAL_REQUIRE_DATA(path, "hesai/xt32_dual.pcap");
  const Capture capture = loadCapture(path);
  const std::set<std::size_t> dropped = {100, 101, 102, 700, 1500};
  HesaiDecoder decoder(configFor("PandarXT32"));
  DecodedPacket out;
  std::uint64_t lost = 0;
  std::uint64_t previous_key = 0;
  for (std::size_t i = 0; i < capture.size(); ++i) {
    if (dropped.count(i)) continue;
    decoder.decode(capture.packet(i), out);
    ASSERT_EQ(out.kind, DecodedPacket::Kind::kData);
    EXPECT_EQ(out.order_key, 301676u + i) << "order_key is the udp_sequence";
    if (i == 103) {
      EXPECT_EQ(out.lost_before, 3u);
    } else if (i == 701 || i == 1501) {
      EXPECT_EQ(out.lost_before, 1u);
    } else {
      EXPECT_EQ(out.lost_before, 0u);
    }
    EXPECT_GT(out.order_key, previous_key);
    previous_key = out.order_key;
    lost += out.lost_before;
  }
  EXPECT_EQ(lost, dropped.size());

  // Through the assembler: the sweeps that lost packets say so.
  HesaiDecoder again(configFor("PandarXT32"));
  AssemblerStats stats;
  const auto scans = hesai_test::decodeScans(again, capture, [&](std::size_t i) { return !dropped.count(i); }, 0.0, &stats);
  EXPECT_EQ(stats.lost_packets, dropped.size());
  std::uint32_t missing = 0;
  for (const Scan& s : scans) missing += s.missing_packets;
  EXPECT_EQ(missing, dropped.size());
}

TEST(HesaiDecoder, ReorderedAndDuplicatePacketsAreNotLosses) {
  RIGCAL_REQUIRE_DATA(path, "hesai/qt128_laststrongest.pcap");
  const Capture capture = loadCapture(path);
  HesaiDecoder decoder(configFor("PandarQT128", path.parent_path() / "PandarQT128.csv"));
  DecodedPacket out;
  std::vector<std::size_t> sequence = {0, 1, 3, 2, 4, 4, 5};
  std::vector<std::uint32_t> lost;
  std::vector<std::uint64_t> keys;
  std::size_t points = 0;
  for (std::size_t i : sequence) {
    decoder.decode(capture.packet(i), out);
    ASSERT_EQ(out.kind, DecodedPacket::Kind::kData);
    lost.push_back(out.lost_before);
    keys.push_back(out.order_key);
    points += out.points.size();
  }
  EXPECT_EQ(lost, (std::vector<std::uint32_t>{0, 0, 1, 0, 0, 0, 0}));
  EXPECT_EQ(keys[3], 6394573u + 2);
  EXPECT_EQ(keys[5], 6394573u + 4);
  EXPECT_GE(decoder.stats().late_firings, 2u);
  EXPECT_EQ(decoder.stats().crc_errors, 0u);
  decoder.flush(out);
  EXPECT_GT(points + out.points.size(), 0u);
}

TEST(HesaiDecoder, SensorClockTimesFollowTheTailAndTheFiringTable) {
  RIGCAL_REQUIRE_DATA(path, "hesai/qt128_laststrongest.pcap");
  const Capture capture = loadCapture(path);
  HesaiDecoder decoder(configFor("PandarQT128", path.parent_path() / "PandarQT128.csv"));
  // First packet: 2020-10-09 12:03:29 + 403019 µs, dual return, mode flag 0 → firing sequence 2.
  const TimeNs t0 = 1'602'245'009LL * kNsPerSec + 403'019 * kNsPerUs;
  const DecodedPacket out = decodeAlone(decoder, capture.packet(0));
  ASSERT_EQ(out.kind, DecodedPacket::Kind::kData);
  ASSERT_FALSE(out.points.empty());
  EXPECT_EQ(out.packet_time_ns, t0 + 9'000 + 600);
  std::set<int> seen;
  for (const Point& p : out.points) {
    EXPECT_EQ(p.time_ns, t0 + 9'000 + hesai::qt128LoopOffsetNs(2, p.ring)) << "ring " << p.ring;
    EXPECT_FALSE(p.ring >= 32 && p.ring < 64) << "channels 33-64 do not fire in sequence 2";
    seen.insert(p.ring);
  }
  EXPECT_GT(seen.size(), 60u);
  // Second packet: mode flag 1 → sequence 1.
  const DecodedPacket second = decodeAlone(decoder, capture.packet(1));
  for (const Point& p : second.points) {
    EXPECT_EQ(p.time_ns - second.packet_time_ns, hesai::qt128LoopOffsetNs(1, p.ring) - 600) << p.ring;
    EXPECT_FALSE(p.ring < 32);
  }
}

TEST(HesaiDecoder, XtTimesUnderBothTimeSources) {
  RIGCAL_REQUIRE_DATA(path, "hesai/xt32_dual.pcap");
  const Capture capture = loadCapture(path);
  // Sensor clock: 2019-07-25 03:19:29 + 619165 µs; blocks 1 & 2 fired 150 µs before blocks 7 & 8.
  HesaiDecoder sensor(configFor("PandarXT32"));
  const TimeNs t0 = 1'564'024'769LL * kNsPerSec + 619'165 * kNsPerUs;
  const DecodedPacket out = decodeAlone(sensor, capture.packet(0));
  ASSERT_FALSE(out.points.empty());
  EXPECT_EQ(out.packet_time_ns, t0 + 5'632 - 150'000 + 368);
  TimeNs lo = out.points[0].time_ns, hi = lo;
  for (const Point& p : out.points) {
    const TimeNs rel = p.time_ns - t0;
    const TimeNs in_round = (rel - 5'632 - 368) % 50'000;  // channel part within the 50 µs round
    EXPECT_EQ(((in_round + 50'000) % 50'000), 1'512 * p.ring) << "ring " << p.ring;
    lo = std::min(lo, p.time_ns), hi = std::max(hi, p.time_ns);
  }
  EXPECT_GE(lo, t0 - 150'000);
  EXPECT_LE(hi, t0 + 5'632 + 368 + 31 * 1'512);

  // Host receive: the receive time is taken as the packet's last firing.
  DecoderConfig host = configFor("PandarXT32");
  host.time_source = TimeSource::kHostReceive;
  HesaiDecoder receive(host);
  const UdpPacket packet = capture.packet(0);
  const DecodedPacket h = decodeAlone(receive, packet);
  ASSERT_EQ(h.points.size(), out.points.size());
  const TimeNs shift = packet.receive_ns - (t0 + 5'632 + 368 + 31 * 1'512);
  EXPECT_EQ(h.packet_time_ns, out.packet_time_ns + shift);
  for (std::size_t i = 0; i < h.points.size(); ++i) {
    EXPECT_EQ(h.points[i].time_ns, out.points[i].time_ns + shift);
    EXPECT_LE(h.points[i].time_ns, packet.receive_ns);
  }
  // 2023-01-11 (pcap record time), nothing like the sensor's 2019 clock.
  EXPECT_GT(h.packet_time_ns, 1'673'000'000LL * kNsPerSec);
}

// Edits one XT16 packet (no azimuth offsets): every firing at `azimuth` (0.01°), channel `c`'s two
// returns set to raw distances d1, d2 (4 mm units), all other channels empty.
std::vector<std::uint8_t> xt16Packet(const std::vector<std::uint8_t>& base, int azimuth, int c, int d1, int d2) {
  std::vector<std::uint8_t> p = base;
  for (int b = 0; b < 8; ++b) {
    std::uint8_t* block = p.data() + 12 + b * (2 + 16 * 4);
    block[0] = static_cast<std::uint8_t>(azimuth), block[1] = static_cast<std::uint8_t>(azimuth >> 8);
    for (int ch = 0; ch < 16; ++ch) {
      const int d = ch != c ? 0 : (b % 2 == 0 ? d1 : d2);
      block[2 + 4 * ch] = static_cast<std::uint8_t>(d), block[3 + 4 * ch] = static_cast<std::uint8_t>(d >> 8);
      block[4 + 4 * ch] = static_cast<std::uint8_t>(10 + b % 2);
    }
  }
  return p;
}

TEST(HesaiDecoder, AxesAreXForwardYLeftZUp) {
  RIGCAL_REQUIRE_DATA(path, "hesai/xt16_dual.pcap");
  const Capture capture = loadCapture(path);
  HesaiDecoder decoder(configFor("PandarXT16"));  // nominal: channel 8 (index 7) at +1°
  const double r = 2500 * 0.004;
  struct Case {
    int azimuth;
    double x, y;
  };
  // Hesai azimuth turns clockwise seen from above: 0° ahead, 90° to the right.
  for (const Case& c : {Case{0, 1, 0}, Case{9000, 0, -1}, Case{18000, -1, 0}, Case{27000, 0, 1}}) {
    UdpPacket packet = capture.packet(0);
    const auto payload = xt16Packet(capture.payloads[0], c.azimuth, 7, 0, 2500);
    packet.payload = payload;
    const DecodedPacket out = decodeAlone(decoder, packet);
    ASSERT_EQ(out.points.size(), 4u) << "one point per firing";
    const double e = 1.0 * kPi / 180.0;
    EXPECT_NEAR(out.points[0].x, r * std::cos(e) * c.x, 1e-4) << c.azimuth;
    EXPECT_NEAR(out.points[0].y, r * std::cos(e) * c.y, 1e-4) << c.azimuth;
    EXPECT_NEAR(out.points[0].z, r * std::sin(e), 1e-4);
    EXPECT_EQ(out.points[0].ring, 7);
    EXPECT_EQ(out.points[0].intensity, 11.f);
    EXPECT_EQ(out.points[0].return_index, 1);
  }
}

TEST(HesaiDecoder, DualReturnRules) {
  RIGCAL_REQUIRE_DATA(path, "hesai/xt16_dual.pcap");
  const Capture capture = loadCapture(path);
  struct Case {
    int d1, d2;
    std::size_t points_per_firing;
    const char* why;
  };
  for (const Case& c : {Case{2500, 2500, 1, "identical returns: keep one"},
                        Case{2500, 2480, 1, "first within 0.1 m of the last: dropped"},
                        Case{2500, 2524, 1, "0.096 m apart: dropped"},
                        Case{2500, 2600, 2, "0.4 m apart: both kept"},
                        Case{0, 2600, 1, "no first return"},
                        Case{2500, 0, 1, "no last return: the first stays"},
                        Case{2500, 40000, 1, "last beyond the sensor's 120 m: only the first"}}) {
    HesaiDecoder decoder(configFor("PandarXT16"));
    UdpPacket packet = capture.packet(0);
    const auto payload = xt16Packet(capture.payloads[0], 1000, 3, c.d1, c.d2);
    packet.payload = payload;
    const DecodedPacket out = decodeAlone(decoder, packet);
    EXPECT_EQ(out.points.size(), 4 * c.points_per_firing) << c.why;
  }
}

TEST(HesaiDecoder, RangeLimitsCombineConfigAndSensor) {
  RIGCAL_REQUIRE_DATA(path, "hesai/xt16_dual.pcap");
  const Capture capture = loadCapture(path);
  DecoderConfig config = configFor("PandarXT16");
  config.min_range_m = 1.0f;
  config.max_range_m = 300.0f;
  for (const auto& [raw, kept] : std::vector<std::pair<int, bool>>{{240, false}, {260, true}, {29000, true}, {31000, false}}) {
    HesaiDecoder decoder(config);
    UdpPacket packet = capture.packet(0);
    const auto payload = xt16Packet(capture.payloads[0], 1000, 3, 0, raw);
    packet.payload = payload;
    EXPECT_EQ(decodeAlone(decoder, packet).points.size(), kept ? 4u : 0u) << raw * 0.004 << " m";
  }
}

TEST(HesaiDecoder, AzimuthJumpsRestartTheOrderingWithoutLosingPoints) {
  RIGCAL_REQUIRE_DATA(path, "hesai/qt128_laststrongest.pcap");
  const Capture capture = loadCapture(path);
  const DecoderConfig config = configFor("PandarQT128", path.parent_path() / "PandarQT128.csv");
  auto count = [&](const std::vector<std::size_t>& order, HesaiDecoder& decoder) {
    DecodedPacket out;
    std::size_t n = 0;
    for (std::size_t i : order) {
      decoder.decode(capture.packet(i), out);
      EXPECT_EQ(out.points.size(), out.azimuth_deg.size());
      n += out.points.size();
    }
    decoder.flush(out);
    return n + out.points.size();
  };
  std::vector<std::size_t> forward(capture.size());
  std::iota(forward.begin(), forward.end(), 0);
  // Packets 600-1199 first: the rotor appears to jump back by 120°, then forward by 240°.
  std::vector<std::size_t> jumbled(forward.begin() + 600, forward.begin() + 1200);
  jumbled.insert(jumbled.end(), forward.begin(), forward.begin() + 600);
  jumbled.insert(jumbled.end(), forward.begin() + 1200, forward.end());
  HesaiDecoder a(config), b(config);
  const std::size_t in_order = count(forward, a);
  EXPECT_EQ(count(jumbled, b), in_order);
  EXPECT_EQ(a.stats().discontinuities, 0u);
  EXPECT_GE(b.stats().discontinuities, 1u);
}

// With the cut at 180°, every full sweep starts with the points whose own azimuth is just past 180°
// and ends with those just short of it, although QT128 channel offsets reach ±10°.
TEST(HesaiDecoder, SweepsAreCutByEachPointsOwnAzimuth) {
  RIGCAL_REQUIRE_DATA(path, "hesai/qt128_laststrongest.pcap");
  const Capture capture = loadCapture(path);
  DecoderConfig config = configFor("PandarQT128", path.parent_path() / "PandarQT128.csv");
  config.min_range_m = 0.3f;
  std::size_t decoded = 0;
  {
    HesaiDecoder plain(config);
    DecodedPacket out;
    for (std::size_t i = 0; i < capture.size(); ++i) plain.decode(capture.packet(i), out), decoded += out.points.size();
    plain.flush(out);
    decoded += out.points.size();
  }
  HesaiDecoder decoder(config);
  const auto scans = hesai_test::decodeScans(decoder, capture, 180.0);
  ASSERT_EQ(scans.size(), 3u);
  std::size_t total = 0;
  for (const Scan& s : scans) total += s.size();
  EXPECT_EQ(total, decoded) << "every decoded point is in some sweep";
  EXPECT_GT(decoded, 140'000u);
  const Scan& full = scans[1];
  std::size_t checked = 0;
  for (std::size_t i = 0; i < full.size(); ++i) {
    // Native azimuth, clockwise from ahead: az = atan2(−y, x).
    double az = std::atan2(-full.y[i], full.x[i]) * 180.0 / kPi;
    if (az < 0) az += 360.0;
    const double past_cut = az - 180.0;
    const double t = double(full.offset_ns[i]) * 1e-9;
    if (past_cut > 0.02 && past_cut < 15.0) {
      EXPECT_LT(t, 0.05);
      ++checked;
    }
    if (past_cut < -0.02 && past_cut > -15.0) {
      EXPECT_GT(t, 0.05);
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000u);
}

}  // namespace
}  // namespace rigcal::drivers
