#include <gtest/gtest.h>

#include <vector>

#include "rigcal/drivers/ipv4_reassembler.hpp"
#include "rigcal/drivers/link_layer.hpp"

namespace rigcal::drivers {
namespace {

// Builds an Ethernet frame (optionally VLAN-tagged) carrying one IPv4 fragment of a UDP datagram.
std::vector<std::uint8_t> frame(const std::vector<std::uint8_t>& ip_payload, std::uint16_t frag_offset,
                                bool more, int vlan_tags) {
  std::vector<std::uint8_t> f(12, 0xaa);
  f.reserve(12 + 4 * std::size_t(vlan_tags) + 22 + ip_payload.size());
  const auto append = [&f](std::initializer_list<std::uint8_t> bytes) {
    for (std::uint8_t b : bytes) f.push_back(b);
  };
  for (int i = 0; i < vlan_tags; ++i) append({0x81, 0x00, 0x00, 0x05});
  append({0x08, 0x00});
  const std::size_t total = 20 + ip_payload.size();
  const std::uint16_t ff = std::uint16_t((more ? 0x2000 : 0) | (frag_offset / 8));
  append({0x45, 0, std::uint8_t(total >> 8), std::uint8_t(total), 0x12, 0x34, std::uint8_t(ff >> 8),
          std::uint8_t(ff), 64, 17, 0, 0, 10, 5, 5, 1, 10, 5, 5, 2});
  for (std::uint8_t b : ip_payload) f.push_back(b);
  return f;
}

std::vector<std::uint8_t> udpDatagram(std::size_t payload_size) {
  const std::size_t len = 8 + payload_size;
  std::vector<std::uint8_t> d{0x1d, 0x4c, 0x1d, 0x4e, std::uint8_t(len >> 8), std::uint8_t(len), 0, 0};
  for (std::size_t i = 0; i < payload_size; ++i) d.push_back(std::uint8_t(i * 7));
  return d;
}

TEST(LinkLayer, ParsesEthernetWithStackedVlanTags) {
  const auto d = udpDatagram(10);
  for (int tags : {0, 1, 2}) {
    Ipv4Header ip;
    const auto f = frame(d, 0, false, tags);  // ip.payload points into it
    ASSERT_EQ(parseFrame(LinkType::kEthernet, f, ip), FrameResult::kIpv4);
    EXPECT_EQ(ip.source, 0x0a050501u);
    const auto udp = parseUdp(ip.payload);
    ASSERT_TRUE(udp);
    EXPECT_EQ(udp->destination_port, 7502);
    EXPECT_EQ(udp->payload.size(), 10u);
  }
}

TEST(LinkLayer, ParsesLinuxCookedCapturesV1AndV2) {
  const auto eth = frame(udpDatagram(12), 0, false, 0);
  const std::vector<std::uint8_t> ip(eth.begin() + 14, eth.end());
  std::vector<std::uint8_t> sll1(16, 0);  // SLL v1: protocol in bytes 14..15
  sll1[14] = 0x08;
  sll1.insert(sll1.end(), ip.begin(), ip.end());
  std::vector<std::uint8_t> sll2(20, 0);  // SLL v2: protocol in bytes 0..1
  sll2[0] = 0x08;
  sll2.insert(sll2.end(), ip.begin(), ip.end());
  for (const auto& [link, bytes] : {std::pair{LinkType::kLinuxSll, sll1}, std::pair{LinkType::kLinuxSll2, sll2}}) {
    Ipv4Header header;
    ASSERT_EQ(parseFrame(link, bytes, header), FrameResult::kIpv4);
    const auto udp = parseUdp(header.payload);
    ASSERT_TRUE(udp);
    EXPECT_EQ(udp->payload.size(), 12u);
  }
  std::vector<std::uint8_t> arp = sll1;
  arp[15] = 0x06;  // 0x0806: ARP
  Ipv4Header header;
  EXPECT_EQ(parseFrame(LinkType::kLinuxSll, arp, header), FrameResult::kNotIpv4);
  EXPECT_EQ(parseFrame(LinkType::kRaw, ip, header), FrameResult::kIpv4);
}

TEST(LinkLayer, TruncatedFramesAreMalformedAtEveryLength) {
  const auto f = frame(udpDatagram(40), 0, false, 1);
  for (std::size_t n = 0; n < f.size(); ++n) {
    Ipv4Header ip;
    const auto r = parseFrame(LinkType::kEthernet, std::span(f.data(), n), ip);
    if (r == FrameResult::kIpv4) {
      EXPECT_FALSE(parseUdp(ip.payload).has_value()) << n;
    }
  }
}

TEST(Ipv4Reassembler, ReassemblesOutOfOrderFragmentsAndBoundsMemory) {
  const auto d = udpDatagram(3000);
  Ipv4Reassembler r(4);
  auto fragment = [&](std::size_t begin, std::size_t end) {
    Ipv4Header ip;
    const auto f = frame(std::vector<std::uint8_t>(d.begin() + long(begin), d.begin() + long(end)),
                         std::uint16_t(begin), end < d.size(), 0);
    EXPECT_EQ(parseFrame(LinkType::kEthernet, f, ip), FrameResult::kIpv4);
    const auto whole = r.add(ip);
    return std::vector<std::uint8_t>(whole.begin(), whole.end());
  };
  EXPECT_TRUE(fragment(2960, d.size()).empty());
  EXPECT_TRUE(fragment(0, 1480).empty());
  const auto whole = fragment(1480, 2960);
  EXPECT_EQ(whole, d);
  EXPECT_EQ(r.dropped(), 0u);
}

}  // namespace
}  // namespace rigcal::drivers
