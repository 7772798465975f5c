// The packet message families no shared bag holds (nebula_msgs/NebulaPackets, ouster PacketMsg), written
// around real capture payloads, and RoboSense's DIFOP flag on the real Helios bag.
#include <gtest/gtest.h>

#include "cdr_test_writer.hpp"
#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/packet_scan_message.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "test_data.hpp"

namespace rigcal::bag {
namespace {

using test::CdrWriter;

struct Captured {
  std::vector<std::vector<std::uint8_t>> payloads;
  std::vector<TimeNs> stamps;
  std::vector<std::uint16_t> ports;
};

Captured capture(const std::filesystem::path& pcap, std::size_t limit) {
  Captured c;
  drivers::PcapSource source(pcap);
  while (const auto p = source.next()) {
    if (c.payloads.size() == limit) break;
    c.payloads.emplace_back(p->payload.begin(), p->payload.end());
    c.stamps.push_back(p->receive_ns);
    c.ports.push_back(p->destination.port);
  }
  return c;
}

TEST(PacketScanMessage, NebulaPacketsCarryEachPacketsBytesAndStamp) {
  RIGCAL_REQUIRE_DATA(pcap, "hesai/xt32_dual.pcap");
  const Captured c = capture(pcap, 50);
  CdrWriter w;
  w.putHeader(c.stamps.front(), "hesai").put(std::uint32_t(c.payloads.size()));
  for (std::size_t i = 0; i < c.payloads.size(); ++i)
    w.put(std::int32_t(c.stamps[i] / kNsPerSec)).put(std::uint32_t(c.stamps[i] % kNsPerSec))
        .put(std::uint32_t(c.payloads[i].size())).putBytes(c.payloads[i]);
  ASSERT_EQ(packetMessageType("nebula_msgs/msg/NebulaPackets"), PacketMessageType::kNebulaPackets);
  std::vector<ScanPacket> packets;
  decodePacketMessage(PacketMessageType::kNebulaPackets, w.bytes(), 0, "nebula", packets);
  ASSERT_EQ(packets.size(), c.payloads.size());
  for (std::size_t i = 0; i < packets.size(); ++i) {
    EXPECT_EQ(packets[i].stamp_ns, c.stamps[i]);
    EXPECT_TRUE(std::equal(packets[i].data.begin(), packets[i].data.end(), c.payloads[i].begin(), c.payloads[i].end()));
  }
}

TEST(PacketScanMessage, OusterPacketMsgIsOnePacketAtTheLogTime) {
  RIGCAL_REQUIRE_DATA(pcap, "ouster/OS-1-64_1024x10_fw20.pcap");
  const Captured c = capture(pcap, 1);
  ASSERT_EQ(c.payloads.size(), 1u);
  CdrWriter w;
  w.put(std::uint32_t(c.payloads[0].size())).putBytes(c.payloads[0]);
  for (const char* type : {"ouster_sensor_msgs/msg/PacketMsg", "ouster_ros/msg/PacketMsg"})
    EXPECT_EQ(packetMessageType(type), PacketMessageType::kOusterPacket) << type;
  std::vector<ScanPacket> packets;
  decodePacketMessage(PacketMessageType::kOusterPacket, w.bytes(), 1234, "ouster", packets);
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0].stamp_ns, 1234);
  EXPECT_TRUE(std::equal(packets[0].data.begin(), packets[0].data.end(), c.payloads[0].begin(), c.payloads[0].end()));
}

TEST(PacketScanMessage, RobosenseBagFlagsTheDifopPacketsThePcapSendsToPort7788) {
  RIGCAL_REQUIRE_DATA(bag_path, "bags/robosense_helios16p");
  RIGCAL_REQUIRE_DATA(pcap, "robosense/helios16p.pcap");
  const Captured c = capture(pcap, SIZE_MAX);
  std::vector<std::vector<std::uint8_t>> pcap_difop, bag_difop;
  for (std::size_t i = 0; i < c.payloads.size(); ++i)
    if (c.ports[i] == 7788) pcap_difop.push_back(c.payloads[i]);
  Bag bag(bag_path);
  std::vector<ScanPacket> packets;
  while (const auto m = bag.next()) {
    packets.clear();
    decodePacketMessage(PacketMessageType::kRobosenseScan, m->data, m->log_time_ns, "helios", packets);
    for (const auto& p : packets)
      if (p.is_difop) bag_difop.emplace_back(p.data.begin(), p.data.end());
  }
  ASSERT_FALSE(pcap_difop.empty());
  EXPECT_EQ(bag_difop, pcap_difop);
}

}  // namespace
}  // namespace rigcal::bag
