#include "rigcal/bag/packet_scan_message.hpp"

#include "rigcal/bag/cdr_reader.hpp"

namespace rigcal::bag {

namespace {

constexpr std::size_t kVelodynePacketBytes = 1206;
constexpr std::size_t kPacketBufferBytes = 1500;  // Pandar and RoboSense fixed buffers

// A fixed buffer followed by its used size (PandarPacket, RobosensePacket).
std::span<const std::uint8_t> sizedBuffer(CdrReader& cdr) {
  const auto buffer = cdr.take(kPacketBufferBytes, "packets[].data");
  const auto size = cdr.read<std::uint32_t>("packets[].size");
  if (size > buffer.size())
    throw BagError(cdr.what() + ": packet size " + std::to_string(size) + " exceeds its " +
                   std::to_string(buffer.size()) + "-byte buffer");
  return buffer.first(size);
}

}  // namespace

std::optional<PacketMessageType> packetMessageType(std::string_view ros_type) {
  if (ros_type == "velodyne_msgs/msg/VelodyneScan") return PacketMessageType::kVelodyneScan;
  if (ros_type == "pandar_msgs/msg/PandarScan") return PacketMessageType::kPandarScan;
  if (ros_type == "robosense_msgs/msg/RobosenseScan") return PacketMessageType::kRobosenseScan;
  if (ros_type == "nebula_msgs/msg/NebulaPackets") return PacketMessageType::kNebulaPackets;
  if (ros_type == "ouster_sensor_msgs/msg/PacketMsg" || ros_type == "ouster_ros/msg/PacketMsg")
    return PacketMessageType::kOusterPacket;
  return std::nullopt;
}

std::string packetMessageTypeList() {
  return "velodyne_msgs/msg/VelodyneScan, pandar_msgs/msg/PandarScan, robosense_msgs/msg/RobosenseScan, "
         "nebula_msgs/msg/NebulaPackets, ouster_sensor_msgs/msg/PacketMsg";
}

void decodePacketMessage(PacketMessageType type, std::span<const std::uint8_t> message, TimeNs log_time_ns,
                         const std::string& what, std::vector<ScanPacket>& out) {
  CdrReader cdr(message, what);
  if (type == PacketMessageType::kOusterPacket) {
    const auto n = cdr.readCount("buf", 1);
    out.push_back({log_time_ns, cdr.take(n, "buf"), false});
    return;
  }
  cdr.readHeader();
  constexpr std::size_t kStampBytes = 8;
  switch (type) {
    case PacketMessageType::kVelodyneScan: {
      const auto n = cdr.readCount("packets", kStampBytes + kVelodynePacketBytes);
      for (std::uint32_t i = 0; i < n; ++i) {
        const TimeNs stamp = cdr.readTime("packets[].stamp");
        out.push_back({stamp, cdr.take(kVelodynePacketBytes, "packets[].data"), false});
      }
      break;
    }
    case PacketMessageType::kPandarScan: {
      const auto n = cdr.readCount("packets", kStampBytes + kPacketBufferBytes + 4);
      for (std::uint32_t i = 0; i < n; ++i) {
        const TimeNs stamp = cdr.readTime("packets[].stamp");
        out.push_back({stamp, sizedBuffer(cdr), false});
      }
      break;
    }
    case PacketMessageType::kRobosenseScan: {
      const auto n = cdr.readCount("packets", kStampBytes + 1 + kPacketBufferBytes + 4);
      for (std::uint32_t i = 0; i < n; ++i) {
        const TimeNs stamp = cdr.readTime("packets[].stamp");
        const bool difop = cdr.read<std::uint8_t>("packets[].is_difop") != 0;
        out.push_back({stamp, sizedBuffer(cdr), difop});
      }
      break;
    }
    case PacketMessageType::kNebulaPackets: {
      const auto n = cdr.readCount("packets", kStampBytes + 4);
      for (std::uint32_t i = 0; i < n; ++i) {
        const TimeNs stamp = cdr.readTime("packets[].stamp");
        const auto size = cdr.readCount("packets[].data", 1);
        out.push_back({stamp, cdr.take(size, "packets[].data"), false});
      }
      break;
    }
    case PacketMessageType::kOusterPacket:
      break;
  }
}

}  // namespace rigcal::bag
