#pragma once
// Which lidar model recorded a packet, from the packet alone, for `rigcal rig-from-bag`'s starter rig:
// Velodyne by the factory byte, Hesai by the first model whose packet layout accepts it, RoboSense by
// the MSOP header, Ouster by the packet size (channel count; the OS0/OS1/OS2 variant cannot be told).
#include <cstdint>
#include <span>
#include <string>

#include "rigcal/bag/packet_scan_message.hpp"

namespace rigcal::bag {

struct ModelGuess {
  std::string model;  // a name makeDecoder accepts, empty when unknown
  std::string note;   // what the user must check
};

ModelGuess guessModelFromPacket(PacketMessageType type, std::span<const std::uint8_t> payload);

/// From a PointCloud2's ring count (max ring + 1) and frame/topic name: only a hint.
ModelGuess guessModelFromCloud(std::size_t rings, const std::string& name);

}  // namespace rigcal::bag
