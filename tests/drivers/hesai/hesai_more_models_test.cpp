// Pandar40P, Pandar64, PandarQT64 and PandarXT32M: their packet formats read from real captures,
// their firing-time tables, and bad packets counted and dropped.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "hesai_test_util.hpp"
#include "rigcal/drivers/hesai/hesai_packet.hpp"
#include "rigcal/drivers/hesai/hesai_firing_times.hpp"
#include "test_data.hpp"

namespace rigcal::drivers::hesai {
namespace {

using hesai_test::Capture;
using hesai_test::firstPayload;
using hesai_test::loadCapture;

struct NewModel {
  const char* name;
  const char* capture;
  const char* calibration;
  std::size_t packet_bytes;
};

constexpr std::array<NewModel, 4> kNewModels{{
    {"Pandar40P", "pandar40p_dual.pcap", "Pandar40P.csv", 1262},
    {"Pandar64", "pandar64_dual.pcap", "Pandar64.csv", 1198},
    {"PandarQT64", "pandarqt64_dual.pcap", "PandarQT64.csv", 1072},
    {"PandarXT32M", "xt32m_laststrongest.pcap", "PandarXT32M.csv", 820},
}};

const ModelSpec& spec(const char* name) {
  const ModelSpec* s = findModel(name);
  EXPECT_NE(s, nullptr) << name;
  return *s;
}

TEST(HesaiMoreModels, RealPacketsParseWithTheirTailFields) {
  RIGCAL_REQUIRE_DATA(p40, "hesai/pandar40p_dual.pcap");
  RIGCAL_REQUIRE_DATA(p64, "hesai/pandar64_dual.pcap");
  RIGCAL_REQUIRE_DATA(qt64, "hesai/pandarqt64_dual.pcap");
  RIGCAL_REQUIRE_DATA(xt32m, "hesai/xt32m_laststrongest.pcap");
  PacketView v;

  auto p = firstPayload(p40);
  ASSERT_EQ(p.size(), 1262u);
  ASSERT_EQ(parsePacket(spec("Pandar40P"), p, v), "");
  EXPECT_EQ(v.returns, 2);
  EXPECT_EQ(v.return_mode, return_mode::kLastStrongest);
  EXPECT_EQ(v.dis_unit_mm, 4);
  EXPECT_EQ(v.unit_bytes, 3);
  EXPECT_EQ(v.motor_rpm, 600);
  EXPECT_EQ(v.azimuth(0), 147);
  EXPECT_EQ(v.azimuth(9), 227);
  EXPECT_EQ(v.timestamp_us, 881567u);
  EXPECT_FALSE(v.udp_sequence);  // this unit sends the 1262-byte form, without the sequence
  // Year byte 17 counts from 2000: 2017-09-06 16:19:46 UTC.
  EXPECT_EQ(utcSeconds(v.date, yearBase(spec("Pandar40P"), v.date[0])), 1'504'714'786);

  p = firstPayload(p64);
  ASSERT_EQ(parsePacket(spec("Pandar64"), p, v), "");
  EXPECT_EQ(v.returns, 2);
  EXPECT_EQ(v.dis_unit_mm, 4);
  EXPECT_EQ(v.motor_rpm, 599);
  EXPECT_EQ(v.azimuth(0), 71);
  EXPECT_EQ(v.timestamp_us, 977341u);
  EXPECT_EQ(v.udp_sequence, 2339721u);
  // Year byte 120: this unit counts from 1900 (the manual says 2000): 2020-06-25 12:02:09 UTC.
  EXPECT_EQ(utcSeconds(v.date, yearBase(spec("Pandar64"), v.date[0])), 1'593'086'529);
  EXPECT_EQ(yearBase(spec("Pandar64"), 20), 2000);
  EXPECT_EQ(yearBase(spec("PandarQT64"), 20), 1900);
  // Without the optional sequence (4 bytes shorter) the packet still parses.
  p.resize(p.size() - 4);
  ASSERT_EQ(parsePacket(spec("Pandar64"), p, v), "");
  EXPECT_FALSE(v.udp_sequence);

  p = firstPayload(qt64);
  ASSERT_EQ(parsePacket(spec("PandarQT64"), p, v), "");
  EXPECT_EQ(v.returns, 2);
  EXPECT_EQ(v.return_mode, return_mode::kFirstLast);
  EXPECT_EQ(v.azimuth(2), 180);
  EXPECT_EQ(v.timestamp_us, 818090u);
  EXPECT_EQ(v.udp_sequence, 165433u);
  EXPECT_EQ(utcSeconds(v.date, 1900), 1'504'708'282);  // 2017-09-06 14:31:22

  p = firstPayload(xt32m);
  ASSERT_EQ(parsePacket(spec("PandarXT32M"), p, v), "");
  EXPECT_EQ(v.returns, 2);  // header return_num says 3; the tail's mode 0x3C fills 2 blocks per firing
  EXPECT_EQ(v.return_mode, return_mode::kFirstStrongest);
  EXPECT_EQ(v.azimuth(4), 108);
  EXPECT_EQ(v.udp_sequence, 80929445u);
  EXPECT_EQ(v.timestamp_us, 850102u);
}

// Consecutive firings of one packet are one firing round apart, and channels follow the tables.
TEST(HesaiMoreModels, FiringTimesFollowTheManualTables) {
  struct Round {
    Model model;
    int blocks;
    std::int64_t round_ns;
  };
  for (const Round r : {Round{Model::kPandar40P, 10, 55'560}, Round{Model::kPandar64, 6, 55'560},
                        Round{Model::kQT64, 4, 166'666}, Round{Model::kXT32M, 6, 50'000}}) {
    for (int returns : {1, 2}) {
      for (int b = returns; b < r.blocks; b += returns) {
        const std::int64_t step =
            firingOffsetNs(r.model, returns, b, 0, 0) - firingOffsetNs(r.model, returns, b - returns, 0, 0);
        EXPECT_NEAR(double(step), double(r.round_ns), 1.0) << int(r.model) << " block " << b;
        if (returns == 2) {  // both returns of one firing share its time
          EXPECT_EQ(firingOffsetNs(r.model, 2, b, 5, 0), firingOffsetNs(r.model, 2, b + 1, 5, 0));
        }
      }
    }
  }
  // Pandar40P / Pandar64: t0 is the last firing round; every laser fires before it.
  for (int c = 0; c < 40; ++c) EXPECT_LT(firingOffsetNs(Model::kPandar40P, 2, 9, c, 0), 0) << c;
  for (int c = 0; c < 64; ++c) EXPECT_LT(firingOffsetNs(Model::kPandar64, 1, 5, c, 0), 0) << c;
  EXPECT_EQ(firingOffsetNs(Model::kPandar40P, 1, 9, 0, 0), -28'580 - 42'220);
  EXPECT_EQ(firingOffsetNs(Model::kPandar64, 1, 0, 63, 0), -42'580 - 5 * 55'560 - 12'748);
  // QT64: t0 is the packet's first round; channels fire in order, 146.45 µs for the whole round.
  for (int c = 1; c < 64; ++c)
    EXPECT_GT(firingOffsetNs(Model::kQT64, 1, 0, c, 0), firingOffsetNs(Model::kQT64, 1, 0, c - 1, 0)) << c;
  EXPECT_EQ(firingOffsetNs(Model::kQT64, 1, 0, 63, 0), 25'710 + 146'450);
  // XT32M: channels c and c + 16 fire together.
  for (int c = 0; c < 16; ++c)
    EXPECT_EQ(firingOffsetNs(Model::kXT32M, 2, 4, c, 0), firingOffsetNs(Model::kXT32M, 2, 4, c + 16, 0));
  EXPECT_EQ(firingOffsetNs(Model::kXT32M, 2, 4, 15, 0), 5'632 + 368 + 15 * 2'888);
}

TEST(HesaiMoreModels, ForeignAndTruncatedPacketsNameTheField) {
  std::vector<std::vector<std::uint8_t>> firsts;
  for (const NewModel& m : kNewModels) {
    RIGCAL_REQUIRE_DATA(path, std::string("hesai/") + m.capture);
    firsts.push_back(firstPayload(path));
  }
  PacketView v;
  for (std::size_t i = 0; i < kNewModels.size(); ++i) {
    const ModelSpec& s = spec(kNewModels[i].name);
    const std::string prefix = std::string(s.name) + " packet: ";
    for (std::size_t j = 0; j < kNewModels.size(); ++j) {
      if (i == j) continue;
      const std::string error = parsePacket(s, firsts[j], v);
      EXPECT_EQ(error.rfind(prefix, 0), 0u) << kNewModels[j].name << " as " << s.name << ": " << error;
      EXPECT_EQ(error.find('\n'), std::string::npos);
    }
    // Every truncation of a good packet is refused (and read nothing past its end: ASan checks).
    for (std::size_t n = 0; n < firsts[i].size(); ++n) {
      if (s.model == Model::kPandar64 && n + 4 == firsts[i].size()) continue;  // legal: no udp_sequence
      const std::vector<std::uint8_t> cut(firsts[i].begin(), firsts[i].begin() + std::ptrdiff_t(n));
      EXPECT_NE(parsePacket(s, cut, v), "") << s.name << " cut to " << n;
    }
  }
  auto p = firsts[0];
  p[2 * 124] = 0x00;  // block 3's 0xFFEE flag
  EXPECT_EQ(parsePacket(spec("Pandar40P"), p, v), "Pandar40P packet: block 3 starts 0x00EE, expected 0xFFEE");
  p = firsts[1];
  p[2] = 40;
  EXPECT_EQ(parsePacket(spec("Pandar64"), p, v), "Pandar64 packet: laser_num 40, expected 64");
  p = firsts[1];
  p[8 + 6 * 194 + 14] = 0x37;  // single return, but block 2 repeats block 1's azimuth: still legal
  EXPECT_EQ(parsePacket(spec("Pandar64"), p, v), "");
  EXPECT_EQ(v.returns, 1);
  p[8 + 6 * 194 + 14] = 0x3D;  // triple return: not decoded here
  EXPECT_EQ(parsePacket(spec("Pandar64"), p, v), "Pandar64 packet: return mode 0x3D unknown");
  p = firsts[2];
  p[11] = 0x00;  // says "no sequence" but carries one
  EXPECT_EQ(parsePacket(spec("PandarQT64"), p, v), "PandarQT64 packet: size 1072, expected 1068 for flags 0x00");
  p = firsts[3];
  p[10] = 4;
  EXPECT_EQ(parsePacket(spec("PandarXT32M"), p, v), "PandarXT32M packet: return_num 4, expected 1 to 3");
}

// A capture with every fifth packet replaced by a damaged copy decodes to the same sweeps as the
// capture without those packets; the damaged ones are counted as malformed.
TEST(HesaiMoreModels, DamagedPacketsAreCountedAndDropped) {
  for (const NewModel& m : kNewModels) {
    RIGCAL_REQUIRE_DATA(path, std::string("hesai/") + m.capture);
    RIGCAL_REQUIRE_DATA(csv, std::string("hesai/") + m.calibration);
    const Capture capture = loadCapture(path);
    Capture damaged = capture;
    std::size_t injected = 0;
    for (std::size_t i = 3; i < damaged.size(); i += 5, ++injected) {
      auto& p = damaged.payloads[i];
      switch (injected % 3) {
        case 0: p.resize(p.size() / 2); break;                  // truncated
        case 1: p.assign(1206, 0xFF); break;                    // foreign (a Velodyne-sized packet)
        default: p.push_back(0); p.push_back(0); break;          // two bytes too long
      }
    }
    DecoderConfig config;
    config.model = m.name;
    config.calibration = csv;
    auto decode = [&](const Capture& c, std::size_t& malformed) {
      HesaiDecoder decoder(config);
      malformed = 0;
      DecodedPacket out;
      std::size_t points = 0;
      for (std::size_t i = 0; i < c.size(); ++i) {
        decoder.decode(c.packet(i), out);
        if (out.kind == DecodedPacket::Kind::kMalformed) {
          ++malformed;
          EXPECT_EQ(out.error.rfind(std::string(m.name) + " packet: ", 0), 0u) << out.error;
          EXPECT_TRUE(out.points.empty());
          continue;
        }
        EXPECT_EQ(out.kind, DecodedPacket::Kind::kData) << m.name << " packet " << i;
        points += out.points.size();
      }
      decoder.flush(out);
      return points + out.points.size();
    };
    std::size_t malformed_clean = 0, malformed_damaged = 0;
    const std::size_t all_points = decode(capture, malformed_clean);
    const std::size_t kept_points = decode(damaged, malformed_damaged);
    EXPECT_EQ(malformed_clean, 0u) << m.name;
    EXPECT_EQ(malformed_damaged, injected) << m.name;
    EXPECT_GT(kept_points, all_points * 3 / 4) << m.name;
    EXPECT_LT(kept_points, all_points) << m.name;
  }
}

}  // namespace
}  // namespace rigcal::drivers::hesai
