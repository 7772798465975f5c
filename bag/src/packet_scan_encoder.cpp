#include "rigcal/bag/packet_scan_encoder.hpp"

#include <stdexcept>
#include <string>

#include "rigcal/bag/cdr_writer.hpp"

namespace rigcal::bag {

namespace {

constexpr std::size_t kVelodynePacketBytes = 1206;
constexpr std::size_t kPacketBufferBytes = 1500;

void checkSize(const ScanPacket& p, std::size_t max, std::string_view type) {
  if (p.data.size() > max)
    throw std::invalid_argument(std::string(type) + ": a packet of " + std::to_string(p.data.size()) +
                                " bytes does not fit its " + std::to_string(max) + "-byte buffer");
}

}  // namespace

std::string_view packetMessageTypeName(PacketMessageType type) {
  switch (type) {
    case PacketMessageType::kVelodyneScan: return "velodyne_msgs/msg/VelodyneScan";
    case PacketMessageType::kPandarScan: return "pandar_msgs/msg/PandarScan";
    case PacketMessageType::kRobosenseScan: return "robosense_msgs/msg/RobosenseScan";
    case PacketMessageType::kNebulaPackets: return "nebula_msgs/msg/NebulaPackets";
    case PacketMessageType::kOusterPacket: return "ouster_sensor_msgs/msg/PacketMsg";
  }
  return {};
}

std::vector<std::uint8_t> encodePacketMessage(PacketMessageType type, TimeNs header_stamp_ns,
                                              std::string_view frame_id, std::span<const ScanPacket> packets) {
  const std::string_view name = packetMessageTypeName(type);
  CdrWriter cdr;
  std::size_t bytes = 64;
  for (const auto& p : packets) bytes += 16 + std::max(p.data.size(), kPacketBufferBytes);
  cdr.reserve(bytes);
  if (type == PacketMessageType::kOusterPacket) {
    if (packets.size() != 1)
      throw std::invalid_argument(std::string(name) + " holds one packet, not " + std::to_string(packets.size()));
    cdr.put(std::uint32_t(packets[0].data.size()));
    cdr.putBytes(packets[0].data);
    return cdr.take();
  }
  cdr.putHeader(header_stamp_ns, frame_id);
  cdr.put(std::uint32_t(packets.size()));
  for (const auto& p : packets) {
    cdr.putTime(p.stamp_ns);
    switch (type) {
      case PacketMessageType::kVelodyneScan:
        if (p.data.size() != kVelodynePacketBytes)
          throw std::invalid_argument(std::string(name) + ": a VelodynePacket is 1206 bytes, not " +
                                      std::to_string(p.data.size()));
        cdr.putBytes(p.data);
        break;
      case PacketMessageType::kRobosenseScan:
        checkSize(p, kPacketBufferBytes, name);
        cdr.put(std::uint8_t(p.is_difop ? 1 : 0));
        [[fallthrough]];
      case PacketMessageType::kPandarScan:
        checkSize(p, kPacketBufferBytes, name);
        cdr.putBytes(p.data);
        cdr.putZeros(kPacketBufferBytes - p.data.size());
        cdr.put(std::uint32_t(p.data.size()));
        break;
      case PacketMessageType::kNebulaPackets:
        cdr.put(std::uint32_t(p.data.size()));
        cdr.putBytes(p.data);
        break;
      case PacketMessageType::kOusterPacket:
        break;
    }
  }
  return cdr.take();
}

}  // namespace rigcal::bag
