// The simulator's packets next to real captures of the same models (shared test data): the fixed
// bytes a decoder or a vendor tool checks — sizes, block/bank headers, factory bytes, header and tail
// fields, status words — are the real sensor's.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/sim/recording.hpp"
#include "sim_test_util.hpp"
#include "test_data.hpp"

namespace rigcal::sim {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::uint16_t u16(const Bytes& b, std::size_t at) { return std::uint16_t(b.at(at) | (b.at(at + 1) << 8)); }

/// The first `count` datagram payloads of `pcap` (of size `size` when given).
std::vector<Bytes> payloads(const std::filesystem::path& pcap, std::size_t count, std::size_t size = 0) {
  drivers::PcapSource source(pcap);
  std::vector<Bytes> out;
  while (out.size() < count) {
    auto p = source.next();
    if (!p) break;
    if (size && p->payload.size() != size) continue;
    out.emplace_back(p->payload.begin(), p->payload.end());
  }
  return out;
}

/// A few packets of `model` from a short simulated drive.
std::vector<Bytes> simulated(const std::string& model, std::size_t count) {
  const Simulation sim(test::movingLidar(model, 5.0, 0.0, 0.02, 0.0, 0.3));
  rigcal::test::TempDir dir;
  SimulationOptions o;
  o.build_scans = false;
  o.max_duration_ns = fromSeconds(0.05);
  writeRecording(sim, makeEncoders(sim), dir / "r.pcap", o);
  return payloads(dir / "r.pcap", count);
}

TEST(WireFormat, VelodyneMatchesRealVlp16Vlp32cAndVls128Packets) {
  struct Case {
    const char* model;
    const char* capture;
    bool same_return_mode;  // the vlp16 capture is dual return; ours is strongest
  };
  for (const Case& c : {Case{"VLP-16", "velodyne/vlp16_dual.pcap", false},
                        Case{"VLP-32C", "velodyne/vlp32c_fov270to90.pcap", true},
                        Case{"VLS-128", "velodyne/vls128_strongest.pcap", true}}) {
    RIGCAL_REQUIRE_DATA(path, c.capture);
    const auto real = payloads(path, 3, 1206), ours = simulated(c.model, 3);
    ASSERT_EQ(real.size(), 3u) << c.capture;
    ASSERT_EQ(ours.size(), 3u) << c.model;
    for (std::size_t k = 0; k < 3; ++k) {
      ASSERT_EQ(ours[k].size(), 1206u) << c.model;
      EXPECT_EQ(ours[k][1205], real[k][1205]) << c.model << ": product id";
      if (c.same_return_mode) {
        EXPECT_EQ(ours[k][1204], real[k][1204]) << c.model << ": return mode";
      }
      for (int b = 0; b < 12; ++b) {
        EXPECT_EQ(u16(ours[k], 100 * b), u16(real[k], 100 * b)) << c.model << ": block " << b << " header";
        EXPECT_LT(u16(ours[k], 100 * b + 2), 36000) << c.model;
      }
      std::uint32_t micros = 0;
      std::memcpy(&micros, ours[k].data() + 1200, 4);
      EXPECT_LT(micros, 3'600'000'000u);
    }
    if (std::string(c.model) == "VLS-128") {
      for (int b = 0; b < 12; ++b)  // the four banks of a firing sequence share its azimuth
        EXPECT_EQ(u16(ours[0], 100 * b + 2), u16(ours[0], 100 * (b / 4 * 4) + 2));
    }
  }
}

TEST(WireFormat, HesaiMatchesARealXt32Packet) {
  RIGCAL_REQUIRE_DATA(path, "hesai/xt32_dual.pcap");
  const auto real = payloads(path, 1, 1080), ours = simulated("PandarXT32", 2);
  ASSERT_EQ(real.size(), 1u);
  ASSERT_EQ(ours.size(), 2u);
  const Bytes &r = real[0], &o = ours[0];
  ASSERT_EQ(o.size(), 1080u);
  for (std::size_t i : {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 11}) EXPECT_EQ(o[i], r[i]) << "header byte " << i;
  EXPECT_EQ(o[10], 1) << "return_num: single return";
  const std::size_t tail = 12 + 8 * 130;
  EXPECT_EQ(o[tail + 10], 0x37) << "strongest return";
  EXPECT_NEAR(u16(o, tail + 11), u16(r, tail + 11), 2) << "motor rpm";
  EXPECT_EQ(o[tail + 23], r[tail + 23]) << "factory byte";
  EXPECT_EQ(o[12 + 2 + 3], r[12 + 2 + 3]) << "channel reserved byte";
  EXPECT_GE(o[tail + 13], 100) << "year since 1900";
  EXPECT_LT(o[tail + 14] - 1u, 12u) << "month";
  std::uint32_t us = 0, seq0 = 0, seq1 = 0;
  std::memcpy(&us, o.data() + tail + 19, 4);
  std::memcpy(&seq0, o.data() + tail + 24, 4);
  std::memcpy(&seq1, ours[1].data() + tail + 24, 4);
  EXPECT_LT(us, 1'000'000u);
  EXPECT_EQ(seq1, seq0 + 1) << "udp_sequence counts packets";
}

TEST(WireFormat, OusterMatchesARealRng19Packet) {
  RIGCAL_REQUIRE_DATA(path, "ouster/OS-2-128-U1_v2.3.0_1024x10.pcap");
  const auto real = payloads(path, 1, 24832), ours = simulated("OS1-128", 2);
  ASSERT_EQ(real.size(), 1u);
  ASSERT_EQ(ours.size(), 2u);
  const Bytes &r = real[0], &o = ours[1];  // ours[0] may be partly covered by the capture's start
  ASSERT_EQ(o.size(), r.size()) << "RNG19, 128 pixels, 16 columns";
  EXPECT_EQ(u16(o, 0), u16(r, 0)) << "packet_type";
  for (std::size_t i = 12; i < 32; ++i) EXPECT_EQ(o[i], r[i]) << "alert/countdown byte " << i;
  const std::size_t column = 12 + 128 * 12;
  for (int c = 0; c < 16; ++c) {
    EXPECT_EQ(u16(o, 32 + c * column + 10), u16(r, 32 + c * column + 10)) << "column status";
    EXPECT_EQ(u16(o, 32 + c * column + 8), u16(o, 32 + 8) + c) << "consecutive measurement ids";
  }
  for (std::size_t i = o.size() - 32; i < o.size(); ++i) EXPECT_EQ(o[i], r[i]) << "footer byte " << i;
}

}  // namespace
}  // namespace rigcal::sim
