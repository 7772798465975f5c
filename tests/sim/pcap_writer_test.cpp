#include <gtest/gtest.h>

#include <fstream>

#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/sim/recording_writer.hpp"
#include "test_data.hpp"

namespace rigcal::sim {
namespace {

using rigcal::test::TempDir;

std::vector<std::uint8_t> pattern(std::size_t n, std::uint8_t seed) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = std::uint8_t(seed + i * 7 + (i >> 8));
  return v;
}

NetEndpoint endpoint(const std::string& ip, std::uint16_t port) {
  return {ipv4FromText(ip), port, macForAddress(ipv4FromText(ip))};
}

// Every frame of a classic pcap file, as (timestamp ns, bytes).
std::vector<std::pair<TimeNs, std::vector<std::uint8_t>>> readFrames(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::vector<std::uint8_t> all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto u32 = [&](std::size_t at) {
    return std::uint32_t(all[at]) | std::uint32_t(all[at + 1]) << 8 | std::uint32_t(all[at + 2]) << 16 |
           std::uint32_t(all[at + 3]) << 24;
  };
  std::vector<std::pair<TimeNs, std::vector<std::uint8_t>>> frames;
  EXPECT_EQ(u32(0), 0xa1b23c4du) << "nanosecond pcap magic";
  EXPECT_EQ(u32(20), 1u) << "Ethernet";
  for (std::size_t at = 24; at + 16 <= all.size();) {
    const TimeNs t = TimeNs(u32(at)) * kNsPerSec + u32(at + 4);
    const std::size_t n = u32(at + 8);
    frames.emplace_back(t, std::vector<std::uint8_t>(all.begin() + std::ptrdiff_t(at + 16),
                                                      all.begin() + std::ptrdiff_t(at + 16 + n)));
    at += 16 + n;
  }
  return frames;
}

TEST(PcapWriter, RoundTripThroughPcapSourceIncludingFragments) {
  TempDir dir;
  const auto file = dir / "out.pcap";
  const NetEndpoint a = endpoint("10.5.5.87", 7502), b = endpoint("192.168.1.201", 2368);
  const NetEndpoint host = endpoint("10.5.5.100", 7502), bcast{0xffffffffu, 2368, {0xff, 0xff, 0xff, 0xff, 0xff, 0xff}};
  const std::vector<std::size_t> sizes = {0, 10, 1206, 1472, 1473, 3000, 8000, 24832};
  const TimeNs t0 = 1'700'000'000'123'456'789;
  {
    PcapWriter w(file);
    for (std::size_t i = 0; i < sizes.size(); ++i) {
      const bool from_a = i % 2 == 0;
      w.writeDatagram(from_a ? a : b, from_a ? host : bcast, pattern(sizes[i], std::uint8_t(i)), t0 + TimeNs(i) * kNsPerMs);
    }
    w.close();
  }
  drivers::PcapSource source(file);
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    const auto p = source.next();
    ASSERT_TRUE(p) << "datagram " << i;
    const bool from_a = i % 2 == 0;
    EXPECT_EQ(p->source.address, (from_a ? a : b).address);
    EXPECT_EQ(p->source.port, (from_a ? a : b).port);
    EXPECT_EQ(p->destination.port, (from_a ? host : bcast).port);
    const auto expected = pattern(sizes[i], std::uint8_t(i));
    ASSERT_EQ(std::vector<std::uint8_t>(p->payload.begin(), p->payload.end()), expected) << "size " << sizes[i];
    EXPECT_GE(p->receive_ns, t0 + TimeNs(i) * kNsPerMs);
  }
  EXPECT_FALSE(source.next());
  EXPECT_EQ(source.stats().fragments_dropped, 0u);
  EXPECT_EQ(source.stats().malformed, 0u);
  EXPECT_TRUE(source.warning().empty());
  // Filtering by source address separates the two senders.
  drivers::PcapSource only_b(file, drivers::PacketFilter{std::nullopt, b.address});
  std::size_t n = 0;
  while (only_b.next()) ++n;
  EXPECT_EQ(n, sizes.size() / 2);
}

TEST(PcapWriter, FramesHaveValidHeadersChecksumsAndFragmentOffsets) {
  TempDir dir;
  const auto file = dir / "frag.pcap";
  {
    PcapWriter w(file);
    w.writeDatagram(endpoint("10.0.0.2", 7502), endpoint("10.0.0.1", 7502), pattern(3000, 1), 5 * kNsPerSec);
    w.writeDatagram(endpoint("10.0.0.2", 7502), endpoint("10.0.0.1", 7502), pattern(20, 2), 6 * kNsPerSec);
    w.close();
  }
  const auto frames = readFrames(file);
  ASSERT_EQ(frames.size(), 4u) << "3008 bytes of UDP at 1480 per fragment: 3 fragments, then 1 frame";
  std::size_t expected_offset = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const auto& f = frames[k].second;
    ASSERT_GE(f.size(), 60u) << "padded to the Ethernet minimum";
    EXPECT_EQ(f[12], 0x08);
    EXPECT_EQ(f[13], 0x00);
    const std::uint8_t* ip = f.data() + 14;
    EXPECT_EQ(ip[0], 0x45);
    EXPECT_EQ(ip[9], 17);
    std::uint32_t sum = 0;
    for (int i = 0; i < 20; i += 2) sum += std::uint32_t(ip[i] << 8 | ip[i + 1]);
    while (sum >> 16) sum = (sum & 0xffff) + (sum >> 16);
    EXPECT_EQ(sum, 0xffffu) << "IPv4 header checksum of frame " << k;
    const std::size_t total = std::size_t(ip[2] << 8 | ip[3]);
    const std::size_t flags_offset = std::size_t(ip[6] << 8 | ip[7]);
    const bool more = flags_offset & 0x2000;
    if (k < 3) {
      EXPECT_EQ(ip[4] << 8 | ip[5], 0) << "one identification per datagram";
      EXPECT_EQ((flags_offset & 0x1fff) * 8, expected_offset);
      EXPECT_EQ(more, k < 2);
      EXPECT_LE(14 + total, 1514u) << "within the MTU";
      expected_offset += total - 20;
    } else {
      EXPECT_EQ(ip[4] << 8 | ip[5], 1) << "identification increments per source";
      EXPECT_EQ(flags_offset, 0u);
      EXPECT_EQ(total, 20u + 8u + 20u);
    }
  }
  EXPECT_EQ(expected_offset, 3008u);
  EXPECT_LT(frames[0].first, frames[1].first) << "fragments follow at wire speed";
  EXPECT_LT(frames[1].first, frames[2].first);
}

TEST(NicClock, StampsAreLateJitteredAndMonotonic) {
  NicClock nic(7, 40'000, 20'000);
  TimeNs last = 0;
  for (int i = 0; i < 1000; ++i) {
    const TimeNs send = 1'000'000 + TimeNs(i) * 3'000;  // faster than the link drains: queueing
    const TimeNs t = nic.stamp(send, 10'000);
    EXPECT_GE(t, send + 40'000);
    EXPECT_GE(t, last);
    last = t + 10'000;
  }
  NicClock a(1), b(1), c(2);
  bool differs = false;
  for (int i = 0; i < 20; ++i) {
    const TimeNs s = TimeNs(i) * kNsPerMs;
    const TimeNs ta = a.stamp(s, 12'000);
    EXPECT_EQ(ta, b.stamp(s, 12'000)) << "seeded";
    differs |= ta != c.stamp(s, 12'000);
    EXPECT_LE(ta, s + 40'000 + 20'000);
  }
  EXPECT_TRUE(differs);
}

TEST(RecordingWriter, MergesSensorsInTrueSendOrderAcrossClockOffsets) {
  TempDir dir;
  const auto file = dir / "rec.pcap";
  // Sensor 1's clock runs 5 ms ahead: its packet stamped 11 ms was sent at true 6 ms.
  RecordingSensor s0{endpoint("10.5.5.87", 7502), endpoint("10.5.5.100", 7502), 0};
  RecordingSensor s1{endpoint("192.168.1.201", 2368), endpoint("192.168.1.255", 2368), 5 * kNsPerMs};
  {
    RecordingWriter w(file, {s0, s1}, 3);
    std::vector<EncodedPacket> p0 = {{pattern(2000, 0), 2 * kNsPerMs}, {pattern(100, 1), 8 * kNsPerMs}};
    std::vector<EncodedPacket> p1 = {{pattern(1206, 2), 11 * kNsPerMs}, {pattern(1206, 3), 12 * kNsPerMs}};
    w.add(0, p0);
    w.add(1, p1);
    EXPECT_TRUE(p0.empty());
    w.flushUntil(7 * kNsPerMs);
    EXPECT_EQ(w.datagrams(), 2u);  // sent at 2 and 6 ms; 7 ms is not before 7 ms
    w.finish();
    EXPECT_EQ(w.datagrams(), 4u);
  }
  drivers::PcapSource source(file);
  std::vector<std::uint8_t> order;
  TimeNs last = 0;
  while (auto p = source.next()) {
    order.push_back(p->payload[0]);
    EXPECT_GE(p->receive_ns, last);
    last = p->receive_ns;
  }
  // First bytes of pattern(n, seed) are the seeds: true send times 2, 6, 7, 8 ms.
  EXPECT_EQ(order, (std::vector<std::uint8_t>{0, 2, 3, 1}));
}

}  // namespace
}  // namespace rigcal::sim
