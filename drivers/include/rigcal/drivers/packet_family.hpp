#pragma once
// Which vendor's packet a UDP payload looks like, from its size and magic bytes alone. A sensor's port that
// receives another model's packets (a Velodyne stream sent to an Ouster sensor's port, two sensors on one
// port) otherwise shows only as "malformed" packets, or worse as points decoded with the wrong layout: the
// drivers count such packets per sensor as foreign and say where they came from (issue 18).
#include <cstdint>
#include <span>
#include <string>

namespace rigcal::drivers {

enum class PacketFamily : std::uint8_t { kUnknown, kVelodyne, kOuster, kHesai, kRobosense };

const char* toString(PacketFamily family);

/// The family of a model name as the rig file gives it ("VLP-16" → kVelodyne, "OS1-64" → kOuster, ...).
PacketFamily familyOfModel(const std::string& model);

/// The family whose signature `payload` carries: Velodyne data (1206 B, every block flagged FF EE/DD/CC/BB),
/// Hesai (900-1400 B starting EE FF; Pandar40P: 1262/1266 B of FF EE blocks), RoboSense (1248 B: MSOP
/// 55 AA 05 0A/5A, DIFOP A5 FF 00 5A). kUnknown otherwise: Ouster lidar packets carry no magic and are never claimed.
PacketFamily recognizePacket(std::span<const std::uint8_t> payload);

}  // namespace rigcal::drivers
