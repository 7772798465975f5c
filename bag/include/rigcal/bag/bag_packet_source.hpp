#pragma once
// A drivers::PacketSource over a bag's packet-scan topic: every packet of every VelodyneScan /
// PandarScan / RobosenseScan / NebulaPackets / ouster PacketMsg message, in log-time order, stamped with
// the packet's recorded receive time, so our decoders and scan assembly run exactly as from a pcap.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/packet_scan_message.hpp"
#include "rigcal/drivers/packet_source.hpp"

namespace rigcal::bag {

class BagPacketSource final : public drivers::PacketSource {
 public:
  /// `topic` empty: the bag's only packet topic. Throws BagError naming the bag when the topic is not in
  /// it or is not a packet type (listing the bag's topics / the accepted types), or when it is ambiguous.
  explicit BagPacketSource(const std::filesystem::path& bag, const std::string& topic = {});

  std::optional<drivers::UdpPacket> next() override;
  [[nodiscard]] const drivers::SourceStats& stats() const override { return stats_; }
  /// A truncated bag, a corrupt chunk met while streaming, or the last malformed message: one line.
  [[nodiscard]] std::string warning() const override;

  [[nodiscard]] const std::string& topic() const { return bag_.topics()[topic_].name; }
  [[nodiscard]] const std::string& type() const { return bag_.topics()[topic_].type; }
  [[nodiscard]] std::uint64_t messages() const { return messages_; }

 private:
  Bag bag_;
  std::size_t topic_ = 0;
  PacketMessageType message_type_ = PacketMessageType::kVelodyneScan;
  std::vector<ScanPacket> pending_;
  std::size_t next_packet_ = 0;
  drivers::SourceStats stats_;
  std::uint64_t messages_ = 0;
  std::string stream_error_, last_malformed_;
};

}  // namespace rigcal::bag
