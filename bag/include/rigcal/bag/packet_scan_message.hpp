#pragma once
// Raw lidar packets recorded as ROS messages, decoded from CDR without ROS, so that our own packet
// decoders see the same payloads as from a pcap. Layouts from the message definitions:
//   velodyne_msgs/VelodyneScan   = Header, VelodynePacket[]{Time stamp, uint8[1206] data}
//   pandar_msgs/PandarScan       = Header, PandarPacket[]{Time stamp, uint8[1500] data, uint32 size}
//   robosense_msgs/RobosenseScan = Header, RobosensePacket[]{Time stamp, uint8 is_difop, uint8[1500] data, uint32 size}
//   nebula_msgs/NebulaPackets    = Header, NebulaPacket[]{Time stamp, uint8[] data}
//   ouster_sensor_msgs/PacketMsg (also ouster_ros/PacketMsg) = uint8[] buf (no stamp: the bag's log time)
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/core/time.hpp"

namespace rigcal::bag {

enum class PacketMessageType { kVelodyneScan, kPandarScan, kRobosenseScan, kNebulaPackets, kOusterPacket };

/// The packet family of a ROS type name ("pandar_msgs/msg/PandarScan"), nullopt when not a packet type.
std::optional<PacketMessageType> packetMessageType(std::string_view ros_type);
/// Every ROS type name packetMessageType accepts (for error messages).
std::string packetMessageTypeList();

struct ScanPacket {
  TimeNs stamp_ns = 0;                 // the packet's receive stamp as the driver recorded it
  std::span<const std::uint8_t> data;  // the UDP payload, a view into the message
  bool is_difop = false;               // RoboSense device-info (DIFOP) packet
};

/// Appends the message's packets to `out`. Throws BagError naming `what` (file/topic/time) and the
/// field when the message is shorter than its layout or a packet's size exceeds its buffer.
void decodePacketMessage(PacketMessageType type, std::span<const std::uint8_t> message, TimeNs log_time_ns,
                         const std::string& what, std::vector<ScanPacket>& out);

}  // namespace rigcal::bag
