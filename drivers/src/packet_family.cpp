#include "rigcal/drivers/packet_family.hpp"

#include <algorithm>

#include "rigcal/drivers/hesai/hesai_decoder.hpp"
#include "rigcal/drivers/ouster/ouster_decoder.hpp"
#include "rigcal/drivers/robosense/robosense_decoder.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"

namespace rigcal::drivers {
namespace {

bool listed(const std::vector<std::string>& models, const std::string& model) {
  return std::find(models.begin(), models.end(), model) != models.end();
}

/// Velodyne data packets: 12 blocks of 100 bytes, each starting with FF and a laser-bank flag.
bool velodyneData(std::span<const std::uint8_t> p) {
  if (p.size() != 1206) return false;
  for (std::size_t b = 0; b < 12; ++b) {
    const std::uint8_t flag = p[100 * b + 1];
    if (p[100 * b] != 0xFF || (flag != 0xEE && flag != 0xDD && flag != 0xCC && flag != 0xBB)) return false;
  }
  return true;
}

}  // namespace

const char* toString(PacketFamily family) {
  switch (family) {
    case PacketFamily::kUnknown: return "unknown";
    case PacketFamily::kVelodyne: return "Velodyne";
    case PacketFamily::kOuster: return "Ouster";
    case PacketFamily::kHesai: return "Hesai";
    case PacketFamily::kRobosense: return "RoboSense";
  }
  return "?";
}

PacketFamily familyOfModel(const std::string& model) {
  if (listed(velodyneModels(), model)) return PacketFamily::kVelodyne;
  if (listed(ousterModels(), model)) return PacketFamily::kOuster;
  if (listed(hesaiModels(), model)) return PacketFamily::kHesai;
  if (listed(robosenseModels(), model)) return PacketFamily::kRobosense;
  return PacketFamily::kUnknown;
}

PacketFamily recognizePacket(std::span<const std::uint8_t> p) {
  // Sizes as well as magic: an Ouster packet (no magic; its first bytes can be anything) is never 1248 B
  // nor in Hesai's 900-1400 B, so random bytes alone never make one foreign.
  if (p.size() == 1248 && p[0] == 0x55 && p[1] == 0xAA && p[2] == 0x05 && (p[3] == 0x0A || p[3] == 0x5A))
    return PacketFamily::kRobosense;
  if (p.size() == 1248 && p[0] == 0xA5 && p[1] == 0xFF && p[2] == 0x00 && p[3] == 0x5A) return PacketFamily::kRobosense;
  if (velodyneData(p)) return PacketFamily::kVelodyne;
  if (p.size() >= 900 && p.size() <= 1400 && p[0] == 0xEE && p[1] == 0xFF) return PacketFamily::kHesai;
  if ((p.size() == 1262 || p.size() == 1266) && p[0] == 0xFF && p[1] == 0xEE) return PacketFamily::kHesai;
  return PacketFamily::kUnknown;
}

}  // namespace rigcal::drivers
