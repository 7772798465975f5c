#include "rigcal/bag/lidar_model_guess.hpp"

#include <algorithm>
#include <cctype>

#include "rigcal/drivers/hesai/hesai_packet.hpp"
#include "rigcal/drivers/robosense/robosense_packet.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"

namespace rigcal::bag {

namespace {

ModelGuess velodyne(std::span<const std::uint8_t> p) {
  if (p.size() != 1206) return {};
  const std::string name = drivers::velodyne::productName(p[drivers::velodyne::kProductIdOffset]);
  if (name == "VLP-16 Hi-Res") return {"VLP-16", "factory byte says VLP-16 Hi-Res: check the calibration"};
  if (name.rfind("0x", 0) == 0) return {"", "unknown Velodyne factory byte " + name};
  return {name, "from the packets' factory byte"};
}

ModelGuess hesai(std::span<const std::uint8_t> p) {
  for (const auto& spec : drivers::hesai::allModels()) {
    drivers::hesai::PacketView view;
    if (drivers::hesai::parsePacket(spec, p, view).empty())
      return {std::string(spec.name), "from the packet layout; give its angle correction CSV"};
  }
  return {};
}

ModelGuess ouster(std::span<const std::uint8_t> p) {
  // 16 columns per packet: LEGACY 16 x (20 + 12 x channels); RNG19_RFL8_SIG16_NIR16 32 + 16 x (12 + 12 x
  // channels) + 32.
  for (const int channels : {16, 32, 64, 128}) {
    if (p.size() == std::size_t(16 * (20 + 12 * channels)) || p.size() == std::size_t(64 + 16 * (12 + 12 * channels)))
      return {"OS1-" + std::to_string(channels),
              "from the packet size (" + std::to_string(channels) + " channels): OS0/OS1/OS2? give its metadata JSON"};
  }
  return {"", "Ouster packet of " + std::to_string(p.size()) + " bytes: unknown profile"};
}

}  // namespace

ModelGuess guessModelFromPacket(PacketMessageType type, std::span<const std::uint8_t> payload) {
  switch (type) {
    case PacketMessageType::kVelodyneScan: return velodyne(payload);
    case PacketMessageType::kPandarScan: return hesai(payload);
    case PacketMessageType::kRobosenseScan:
      if (drivers::robosense::isMsop(payload)) return {"RS-Helios-16P", "from the MSOP header (the only RoboSense model read)"};
      return {};
    case PacketMessageType::kOusterPacket: return ouster(payload);
    case PacketMessageType::kNebulaPackets: {
      // Nebula carries any vendor's packets.
      if (auto g = velodyne(payload); !g.model.empty()) return g;
      if (auto g = hesai(payload); !g.model.empty()) return g;
      if (drivers::robosense::isMsop(payload)) return {"RS-Helios-16P", "from the MSOP header"};
      return {};
    }
  }
  return {};
}

ModelGuess guessModelFromCloud(std::size_t rings, const std::string& name) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  const std::string channels = std::to_string(rings) + " rings";
  if (lower.find("ouster") != std::string::npos || lower.find("os1") != std::string::npos)
    return {"OS1-" + std::to_string(rings), "PointCloud2 with " + channels + " named like an Ouster: check"};
  if (lower.find("hesai") != std::string::npos || lower.find("pandar") != std::string::npos)
    return {rings == 32 ? "PandarXT32" : rings == 64 ? "Pandar64" : rings == 40 ? "Pandar40P" : "",
            "PointCloud2 with " + channels + " named like a Hesai: check"};
  if (lower.find("robosense") != std::string::npos || lower.find("rslidar") != std::string::npos)
    return {"RS-Helios-16P", "PointCloud2 named like a RoboSense: check"};
  switch (rings) {
    case 16: return {"VLP-16", "PointCloud2 with 16 rings: a guess, check"};
    case 32: return {"VLP-32C", "PointCloud2 with 32 rings: a guess, check"};
    case 128: return {"VLS-128", "PointCloud2 with 128 rings: a guess, check"};
    case 64: return {"OS1-64", "PointCloud2 with 64 rings: a guess, check"};
    default: return {"", "PointCloud2 with " + channels + ": set the model"};
  }
}

}  // namespace rigcal::bag
