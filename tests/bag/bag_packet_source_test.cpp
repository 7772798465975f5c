// nebula's packet bags (sqlite3, recorded by Autoware's drivers): the packets decoded from their CDR
// messages are byte for byte the payloads of the matching pcaps, and our decoders turn the bag into the
// same scans as the pcap. Plus the errors a user meets: a topic not in the bag, a non-packet topic, a
// message shorter than its layout.
#include <gtest/gtest.h>

#include <algorithm>

#include "rigcal/bag/bag.hpp"
#include "bag_error_of.hpp"
#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/bag_packet_source.hpp"
#include "rigcal/bag/packet_scan_message.hpp"
#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"
#include "rigcal/drivers/scan_pump.hpp"
#include "test_data.hpp"

namespace rigcal::bag {
namespace {

using test::bagErrorOf;

using Payload = std::vector<std::uint8_t>;

std::vector<Payload> payloadsOf(drivers::PacketSource& source) {
  std::vector<Payload> out;
  while (const auto p = source.next()) out.emplace_back(p->payload.begin(), p->payload.end());
  return out;
}

// Where `bag` occurs in `pcap` as one contiguous run (the pcap may hold more packets around it).
std::optional<std::size_t> runStart(const std::vector<Payload>& pcap, const std::vector<Payload>& bag) {
  if (bag.empty()) return std::nullopt;
  const auto it = std::search(pcap.begin(), pcap.end(), bag.begin(), bag.end());
  if (it == pcap.end()) return std::nullopt;
  return std::size_t(it - pcap.begin());
}

void expectSamePayloads(const std::string& bag_folder, const std::string& pcap, std::size_t payload_size) {
  RIGCAL_REQUIRE_DATA(bag_path, "bags/" + bag_folder);
  RIGCAL_REQUIRE_DATA(pcap_path, pcap);
  BagPacketSource from_bag(bag_path);
  const auto bag_payloads = payloadsOf(from_bag);
  drivers::PcapSource from_pcap(pcap_path);
  const auto pcap_payloads = payloadsOf(from_pcap);
  ASSERT_GT(bag_payloads.size(), 100u);
  EXPECT_EQ(from_bag.stats().malformed, 0u) << from_bag.warning();
  std::size_t data_packets = 0;
  for (const auto& p : bag_payloads) data_packets += p.size() == payload_size ? 1 : 0;
  EXPECT_GE(data_packets, bag_payloads.size() - 1) << "all data packets (RoboSense adds one DIFOP)";
  const auto start = runStart(pcap_payloads, bag_payloads);
  EXPECT_TRUE(start) << bag_folder << ": " << bag_payloads.size() << " packets not found in order in " << pcap << " ("
                     << pcap_payloads.size() << " packets)";
  std::printf("%s: %llu messages, %zu packets = %s packets %zu..%zu of %zu\n", bag_folder.c_str(),
              (unsigned long long)from_bag.messages(), bag_payloads.size(), pcap.c_str(), start.value_or(0),
              start.value_or(0) + bag_payloads.size() - 1, pcap_payloads.size());
}

TEST(BagPacketSource, PandarXT32BagHoldsThePcapsPayloads) {
  expectSamePayloads("nebula_xt32", "hesai/xt32_dual.pcap", 1080);
}
TEST(BagPacketSource, Pandar64BagHoldsThePcapsPayloads) {
  expectSamePayloads("nebula_pandar64", "hesai/pandar64_dual.pcap", 1198);
}
TEST(BagPacketSource, Vlp32BagHoldsThePcapsPayloads) {
  expectSamePayloads("nebula_vlp32", "velodyne/vlp32c_fov270to90.pcap", 1206);
}
TEST(BagPacketSource, Helios16pBagHoldsThePcapsPayloads) {
  expectSamePayloads("robosense_helios16p", "robosense/helios16p.pcap", 1248);
}

struct Decoded {
  std::vector<Scan> scans;
  drivers::AssemblerStats stats;
};

Decoded decodeAll(drivers::PacketSource& source, const drivers::DecoderConfig& config) {
  auto decoder = drivers::makeDecoder(config);
  Decoded d;
  drivers::ScanAssembler assembler(config.model, {}, [&](Scan&& s) { d.scans.push_back(std::move(s)); });
  drivers::pumpScans(source, *decoder, assembler);
  d.stats = assembler.stats();
  return d;
}

bool sameScan(const Scan& a, const Scan& b) {
  return a.stamp_ns == b.stamp_ns && a.x == b.x && a.y == b.y && a.z == b.z && a.intensity == b.intensity &&
         a.ring == b.ring && a.offset_ns == b.offset_ns && a.return_index == b.return_index;
}

// The bags hold exactly the pcaps' packets: every sweep decoded from the bag (partial first and last ones
// included) is identical in points, intensities, rings and times to the pcap's sweep, so the pcap tests'
// match with the vendors' reference decodes carries over to the bags.
void expectSameScans(const std::string& bag_folder, const std::string& pcap, const std::string& model,
                     const std::string& calibration) {
  RIGCAL_REQUIRE_DATA(bag_path, "bags/" + bag_folder);
  RIGCAL_REQUIRE_DATA(pcap_path, pcap);
  drivers::DecoderConfig config;
  config.model = model;
  if (!calibration.empty()) {  // the RS-Helios-16P has none: its angles come in its DIFOP packets
    RIGCAL_REQUIRE_DATA(calibration_path, calibration);
    config.calibration = calibration_path;
  }
  BagPacketSource from_bag(bag_path);
  drivers::PcapSource from_pcap(pcap_path);
  const Decoded bag = decodeAll(from_bag, config);
  const Decoded ref = decodeAll(from_pcap, config);
  ASSERT_GE(bag.scans.size(), 3u);
  ASSERT_EQ(bag.scans.size(), ref.scans.size());
  EXPECT_EQ(bag.stats.malformed, 0u);
  EXPECT_EQ(bag.stats.lost_packets, ref.stats.lost_packets);
  std::size_t identical = 0;
  for (std::size_t i = 0; i < bag.scans.size(); ++i) {
    const bool same = sameScan(bag.scans[i], ref.scans[i]);
    EXPECT_TRUE(same) << bag_folder << ": sweep " << i << " (" << bag.scans[i].size() << " points, stamp "
                      << bag.scans[i].stamp_ns << ") differs from the pcap's (" << ref.scans[i].size() << " points)";
    identical += same ? 1 : 0;
  }
  std::printf("%s: %zu sweeps from the bag, %zu from the pcap; %zu identical\n",
              bag_folder.c_str(), bag.scans.size(), ref.scans.size(), identical);
}

TEST(BagPacketSource, PandarXT32BagDecodesToThePcapsScans) {
  expectSameScans("nebula_xt32", "hesai/xt32_dual.pcap", "PandarXT32", "hesai/PandarXT32.csv");
}
TEST(BagPacketSource, Vlp32BagDecodesToThePcapsScans) {
  expectSameScans("nebula_vlp32", "velodyne/vlp32c_fov270to90.pcap", "VLP-32C", "velodyne/VLP32.calibration.yaml");
}
TEST(BagPacketSource, Pandar64BagDecodesToThePcapsScans) {
  expectSameScans("nebula_pandar64", "hesai/pandar64_dual.pcap", "Pandar64", "hesai/Pandar64.csv");
}
TEST(BagPacketSource, Helios16pBagDecodesToThePcapsScans) {
  expectSameScans("robosense_helios16p", "robosense/helios16p.pcap", "RS-Helios-16P", "");
}

TEST(BagPacketSource, TopicErrorsNameTheBagAndListWhatItHas) {
  RIGCAL_REQUIRE_DATA(xt32, "bags/nebula_xt32");
  RIGCAL_REQUIRE_DATA(talker, "bags/rosbag2/mcap_talker");
  const std::string missing = bagErrorOf([&] { BagPacketSource s(xt32, "/lidar/points"); });
  EXPECT_NE(missing.find("topic /lidar/points not in the bag; it has /pandar_packets"), std::string::npos) << missing;
  const std::string wrong_type = bagErrorOf([&] { BagPacketSource s(talker, "/topic"); });
  EXPECT_NE(wrong_type.find("/topic has type std_msgs/msg/String, not a packet type"), std::string::npos)
      << wrong_type;
  const std::string none = bagErrorOf([&] { BagPacketSource s(talker); });
  EXPECT_NE(none.find("no packet topic"), std::string::npos) << none;
}

// A real PandarScan message cut short: a one-line error naming the field, never a crash.
TEST(BagPacketSource, MessageShorterThanItsLayoutIsAnErrorNamingTheField) {
  RIGCAL_REQUIRE_DATA(xt32, "bags/nebula_xt32");
  Bag bag(xt32);
  const auto m = bag.next();
  ASSERT_TRUE(m);
  std::vector<ScanPacket> packets;
  decodePacketMessage(PacketMessageType::kPandarScan, m->data, m->log_time_ns, "whole", packets);
  ASSERT_GT(packets.size(), 1u);
  for (const std::size_t cut : {std::size_t(2), std::size_t(20), m->data.size() / 2, m->data.size() - 1}) {
    packets.clear();
    const std::string e = bagErrorOf(
        [&] { decodePacketMessage(PacketMessageType::kPandarScan, m->data.first(cut), 0, "xt32 message", packets); });
    EXPECT_NE(e.find("xt32 message:"), std::string::npos) << e;
    EXPECT_TRUE(e.find("shorter than its layout") != std::string::npos || e.find("encapsulation") != std::string::npos)
        << e;
  }
}

}  // namespace
}  // namespace rigcal::bag
