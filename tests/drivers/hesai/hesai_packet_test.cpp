// Packet layouts, validation, CRC, date and firing-time tables (hesai_packet.hpp).
#include <gtest/gtest.h>

#include <set>

#include "hesai_test_util.hpp"
#include "rigcal/drivers/hesai/hesai_packet.hpp"
#include "rigcal/drivers/hesai/hesai_firing_times.hpp"
#include "rigcal/drivers/hesai/hesai_crc.hpp"
#include "test_data.hpp"

namespace rigcal::drivers::hesai {
namespace {

using hesai_test::firstPayload;

const ModelSpec& model(const char* name) {
  const ModelSpec* spec = findModel(name);
  EXPECT_NE(spec, nullptr) << name;
  return *spec;
}

TEST(HesaiPacket, ModelsAndReturnModes) {
  ASSERT_EQ(allModels().size(), 7u);
  EXPECT_EQ(findModel("PandarXT32")->channels, 32);
  EXPECT_EQ(findModel("PandarXT16")->channels, 16);
  EXPECT_EQ(findModel("PandarQT128")->channels, 128);
  EXPECT_EQ(findModel("PandarQT128")->max_range_m, 50.0f);
  EXPECT_EQ(findModel("VLP-16"), nullptr);
  EXPECT_EQ(returnsPerFiring(return_mode::kStrongest), 1);
  EXPECT_EQ(returnsPerFiring(return_mode::kLast), 1);
  EXPECT_EQ(returnsPerFiring(return_mode::kLastStrongest), 2);
  EXPECT_EQ(returnsPerFiring(return_mode::kFirstLast), 2);
  EXPECT_EQ(returnsPerFiring(0x42), 0);
}

// PandarXT manual, Appendix II: t0 triggers the firing stored in block 8 (single) or blocks 7 & 8
// (dual); firing rounds are 50 µs apart and start 5.632 µs after their trigger; channel n fires
// 0.368 + 1.512·(n − 1) µs (XT32) or 0.368 + 3.024·(n − 1) µs (XT16) into the round.
TEST(HesaiPacket, XtFiringTimesFollowTheManual) {
  EXPECT_EQ(firingOffsetNs(Model::kXT32, 1, 7, 0, 0), 5'632 + 368);
  EXPECT_EQ(firingOffsetNs(Model::kXT32, 1, 7, 31, 0), 5'632 + 368 + 31 * 1'512);  // 52.872 µs
  EXPECT_EQ(firingOffsetNs(Model::kXT32, 1, 0, 0, 0), 5'632 - 7 * 50'000 + 368);
  EXPECT_EQ(firingOffsetNs(Model::kXT32, 1, 3, 10, 0), 5'632 - 4 * 50'000 + 368 + 10 * 1'512);
  // Dual: both blocks of a firing share its time.
  EXPECT_EQ(firingOffsetNs(Model::kXT32, 2, 6, 5, 0), firingOffsetNs(Model::kXT32, 2, 7, 5, 0));
  EXPECT_EQ(firingOffsetNs(Model::kXT32, 2, 7, 0, 0), 5'632 + 368);
  EXPECT_EQ(firingOffsetNs(Model::kXT32, 2, 0, 0, 0), 5'632 - 3 * 50'000 + 368);
  EXPECT_EQ(firingOffsetNs(Model::kXT32, 2, 1, 0, 0), 5'632 - 3 * 50'000 + 368);
  EXPECT_EQ(firingOffsetNs(Model::kXT16, 1, 7, 15, 0), 5'632 + 368 + 15 * 3'024);  // 51.36 µs
  EXPECT_EQ(firingOffsetNs(Model::kXT16, 2, 2, 1, 0), 5'632 - 2 * 50'000 + 368 + 3'024);
}

// QT128C2X manual, Appendix II: block start t0 + 9 µs (dual: both blocks; single: block 2, block 1 a
// firing round of 111.11 µs earlier); channel offsets from the firing-sequence table.
TEST(HesaiPacket, Qt128FiringTimesFollowTheFiringSequenceTable) {
  // A few entries of the table (channel numbers 1-based in the manual, 0-based here).
  EXPECT_EQ(qt128LoopOffsetNs(1, 32), 27'656);   // channel 33, sequence 1
  EXPECT_EQ(qt128LoopOffsetNs(1, 34), 2'312);    // channel 35
  EXPECT_EQ(qt128LoopOffsetNs(1, 64), 1'456);    // channel 65
  EXPECT_EQ(qt128LoopOffsetNs(1, 98), 600);      // channel 99: first to fire
  EXPECT_EQ(qt128LoopOffsetNs(2, 0), 2'312);     // channel 1, sequence 2
  EXPECT_EQ(qt128LoopOffsetNs(2, 64), 600);      // channel 65
  EXPECT_EQ(qt128LoopOffsetNs(2, 30), 100'520);  // channel 31: last to fire
  EXPECT_EQ(qt128LoopOffsetNs(1, 5), 0);         // channels 1-32 do not fire in sequence 1
  EXPECT_EQ(qt128LoopOffsetNs(2, 40), 0);        // channels 33-64 do not fire in sequence 2
  // Each sequence fires 96 channels in 32 groups of three: 0.600/1.456/2.312 µs + 3.168 µs per group.
  for (int loop = 1; loop <= 2; ++loop) {
    std::multiset<std::int32_t> offsets;
    for (int c = 0; c < 128; ++c)
      if (qt128LoopOffsetNs(loop, c) != 0) offsets.insert(qt128LoopOffsetNs(loop, c));
    std::multiset<std::int32_t> expected;
    for (int g = 0; g < 32; ++g)
      for (int r = 0; r < 3; ++r) expected.insert(600 + 3'168 * g + 856 * r);
    EXPECT_EQ(offsets, expected) << "loop " << loop;
  }
  EXPECT_EQ(firingOffsetNs(Model::kQT128, 2, 0, 32, 1), 9'000 + 27'656);  // mode flag bit 0: sequence 1
  EXPECT_EQ(firingOffsetNs(Model::kQT128, 2, 1, 32, 1), 9'000 + 27'656);
  EXPECT_EQ(firingOffsetNs(Model::kQT128, 2, 0, 0, 0), 9'000 + 2'312);    // sequence 2
  EXPECT_EQ(firingOffsetNs(Model::kQT128, 1, 0, 32, 0), 9'000 - 111'110 + 27'656);
  EXPECT_EQ(firingOffsetNs(Model::kQT128, 1, 1, 0, 0), 9'000 + 2'312);
}

TEST(HesaiPacket, Crc32Mpeg2CheckValue) {
  const std::string check = "123456789";
  EXPECT_EQ(crc32Mpeg2({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}), 0x0376E6E7u);
  EXPECT_EQ(crc32Mpeg2({}), 0xFFFFFFFFu);
  // The fast paths (slicing-by-16, carry-less multiplication folding) against the bitwise
  // definition, for every length up to 300 bytes and the QT128 body length.
  std::vector<std::uint8_t> input(1028);
  std::uint32_t seed = 12345;
  for (auto& b : input) b = static_cast<std::uint8_t>((seed = seed * 1103515245u + 12345u) >> 24);
  for (std::size_t n = 0; n <= input.size(); n = n < 300 ? n + 1 : input.size() + (n == input.size())) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < n; ++i) {
      c ^= std::uint32_t(input[i]) << 24;
      for (int k = 0; k < 8; ++k) c = (c & 0x80000000u) ? (c << 1) ^ 0x04C11DB7u : (c << 1);
    }
    ASSERT_EQ(crc32Mpeg2({input.data(), n}), c) << "length " << n;
  }
}

TEST(HesaiPacket, UtcSecondsIgnoresTheTimeZone) {
  EXPECT_EQ(utcSeconds({119, 7, 25, 3, 19, 29}), 1'564'024'769);
  EXPECT_EQ(utcSeconds({120, 2, 29, 23, 59, 59}), 1'583'020'799);
  EXPECT_EQ(utcSeconds({70, 1, 1, 0, 0, 0}), 0);
  EXPECT_FALSE(utcSeconds({119, 13, 1, 0, 0, 0}));
  EXPECT_FALSE(utcSeconds({119, 0, 1, 0, 0, 0}));
  EXPECT_FALSE(utcSeconds({119, 1, 0, 0, 0, 0}));
  EXPECT_FALSE(utcSeconds({119, 1, 1, 24, 0, 0}));
  EXPECT_FALSE(utcSeconds({119, 1, 1, 0, 60, 0}));
}

TEST(HesaiPacket, RealPacketsParse) {
  RIGCAL_REQUIRE_DATA(xt32, "hesai/xt32_dual.pcap");
  RIGCAL_REQUIRE_DATA(xt16, "hesai/xt16_dual.pcap");
  RIGCAL_REQUIRE_DATA(qt128, "hesai/qt128_laststrongest.pcap");
  PacketView v;
  auto p = firstPayload(xt32);
  ASSERT_EQ(parsePacket(model("PandarXT32"), p, v), "");
  EXPECT_EQ(v.returns, 2);
  EXPECT_EQ(v.return_mode, return_mode::kLastStrongest);
  EXPECT_EQ(v.dis_unit_mm, 4);
  EXPECT_EQ(v.motor_rpm, 599);
  EXPECT_EQ(v.udp_sequence, 301676u);
  EXPECT_EQ(v.azimuth(0), 108);
  EXPECT_EQ(v.timestamp_us, 619165u);
  EXPECT_FALSE(v.has_crc);
  p = firstPayload(xt16);
  ASSERT_EQ(parsePacket(model("PandarXT16"), p, v), "");
  EXPECT_EQ(v.udp_sequence, 16209614u);
  p = firstPayload(qt128);
  ASSERT_EQ(parsePacket(model("PandarQT128"), p, v), "");
  EXPECT_TRUE(v.has_crc);
  EXPECT_TRUE(v.crc_ok);
  EXPECT_EQ(v.udp_sequence, 6394573u);
  EXPECT_EQ(v.mode_flag, 0);
  EXPECT_EQ(v.azimuth(0), 1080);
}

TEST(HesaiPacket, QtCrcMismatchIsFlaggedNotRejected) {
  RIGCAL_REQUIRE_DATA(qt128, "hesai/qt128_laststrongest.pcap");
  const ModelSpec& spec = model("PandarQT128");
  PacketView v;
  for (std::size_t at : {std::size_t(100), std::size_t(1050), std::size_t(1065)}) {  // body, safety, tail
    auto p = firstPayload(qt128);
    p[at] ^= 0x10;
    EXPECT_EQ(parsePacket(spec, p, v), "") << at;
    EXPECT_FALSE(v.crc_ok) << at;
  }
  auto p = firstPayload(qt128);
  p[1127 - 1] ^= 0xFF;  // the digital signature is not covered by a CRC
  EXPECT_EQ(parsePacket(spec, p, v), "");
  EXPECT_TRUE(v.crc_ok);
}

TEST(HesaiPacket, MalformedPacketsNameTheField) {
  RIGCAL_REQUIRE_DATA(xt32, "hesai/xt32_dual.pcap");
  RIGCAL_REQUIRE_DATA(xt16, "hesai/xt16_dual.pcap");
  RIGCAL_REQUIRE_DATA(qt128, "hesai/qt128_laststrongest.pcap");
  const ModelSpec& spec = model("PandarXT32");
  const auto good = firstPayload(xt32);
  PacketView v;
  auto check = [&](std::vector<std::uint8_t> p, const std::string& expected, const ModelSpec& s) {
    const std::string error = parsePacket(s, p, v);
    EXPECT_NE(error.find(expected), std::string::npos) << "got: " << error;
    EXPECT_EQ(error.rfind(std::string(s.name) + " packet: ", 0), 0u) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos);
  };
  check({}, "size 0, shorter than the 12-byte header", spec);
  check(std::vector<std::uint8_t>(good.begin(), good.end() - 1), "size 1079, expected 1080", spec);
  check(std::vector<std::uint8_t>(good.begin(), good.begin() + 600), "size 600, expected 1080", spec);
  auto p = good;
  p.push_back(0);
  check(p, "size 1081, expected 1080", spec);
  p = good;
  p[0] = 0xFF, p[1] = 0xEE;  // a Velodyne-style block flag
  check(p, "start of packet 0xFFEE, expected 0xEEFF", spec);
  check(firstPayload(xt16), "laser_num 16, expected 32", spec);
  check(firstPayload(qt128), "protocol version 3.2, expected 6.1", spec);
  p = good;
  p[12 + 8 * 130 + 10] = 0x55;
  check(p, "return mode 0x55 unknown", spec);
  p = good;
  p[12 + 8 * 130 + 10] = return_mode::kStrongest;
  check(p, "return mode 0x37 has 1 returns, header return_num 2", spec);
  p = good;
  p[12] = 0xA0, p[13] = 0x8C;  // 36000
  check(p, "block 1 azimuth 36000", spec);
  p = good;
  p[12 + 130] = 0x00, p[13 + 130] = 0x01;
  check(p, "block 2 azimuth 256 differs from its dual-return partner 108", spec);
  p = good;
  p[12 + 8 * 130 + 22] = 0xFF;
  check(p, "timestamp", spec);
  p = good;
  p[9] = 0;
  check(p, "dis_unit 0", spec);
  const ModelSpec& qt = model("PandarQT128");
  p = firstPayload(qt128);
  p[11] |= 0x02;
  check(p, "announce IMU fields", qt);
  p = firstPayload(qt128);
  p[11] &= static_cast<std::uint8_t>(~0x08);  // says "no signature" but carries one
  check(p, "size 1127, expected 1095 for flags 0x15", qt);
  check(std::vector<std::uint8_t>(1206, 0xAB), "start of packet 0xABAB", qt);
}

TEST(HesaiPacket, GpsPacketsAreRecognised) {
  std::vector<std::uint8_t> gps(512, 0);
  gps[0] = 0xFF, gps[1] = 0xEE;
  EXPECT_TRUE(isGpsPacket(gps));
  gps.resize(511);
  EXPECT_FALSE(isGpsPacket(gps));
}

}  // namespace
}  // namespace rigcal::drivers::hesai
