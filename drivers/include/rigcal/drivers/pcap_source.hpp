#pragma once
// Replays UDP datagrams from a capture file (pcap or pcapng, via libpcap) in file order.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "rigcal/drivers/ipv4_reassembler.hpp"
#include "rigcal/drivers/packet_source.hpp"

struct pcap;

namespace rigcal::drivers {

class PcapSource final : public PacketSource {
 public:
  /// Throws std::runtime_error "<file>: <reason>" when the file cannot be opened as a capture or its
  /// link type is not one we read.
  explicit PcapSource(const std::filesystem::path& file, PacketFilter filter = {});
  ~PcapSource() override;
  PcapSource(const PcapSource&) = delete;
  PcapSource& operator=(const PcapSource&) = delete;

  std::optional<UdpPacket> next() override;
  [[nodiscard]] const SourceStats& stats() const override { return stats_; }
  /// Set when the file ended inside a record: the datagrams before the cut were still delivered.
  [[nodiscard]] std::string warning() const override { return warning_; }

 private:
  std::filesystem::path file_;
  PacketFilter filter_;
  pcap* handle_ = nullptr;
  LinkType link_ = LinkType::kEthernet;
  Ipv4Reassembler reassembler_;
  SourceStats stats_;
  std::string warning_;
};

}  // namespace rigcal::drivers
