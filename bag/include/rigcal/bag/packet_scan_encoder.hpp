#pragma once
// The inverse of decodePacketMessage: raw lidar packets serialised as the vendor drivers' ROS 2 scan
// messages (layouts in packet_scan_message.hpp), so a bag of them decodes like the pcap they came from.
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "rigcal/bag/packet_scan_message.hpp"

namespace rigcal::bag {

/// The ROS type name written for `type` ("velodyne_msgs/msg/VelodyneScan", ...).
std::string_view packetMessageTypeName(PacketMessageType type);

/// One scan message holding `packets` (each stamped with its receive time). kOusterPacket takes exactly
/// one packet (that message has no stamp: the bag's log time is its time). Throws std::invalid_argument
/// when a packet does not fit the message (a VelodynePacket is exactly 1206 bytes, Pandar/RoboSense
/// buffers hold 1500).
std::vector<std::uint8_t> encodePacketMessage(PacketMessageType type, TimeNs header_stamp_ns,
                                              std::string_view frame_id, std::span<const ScanPacket> packets);

}  // namespace rigcal::bag
