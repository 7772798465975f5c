#pragma once
// Where UDP payloads come from: a pcap replay (PcapSource) or a live socket (UdpSource).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/drivers/udp_packet.hpp"

namespace rigcal::drivers {

/// Which datagrams a source yields. Two sensors may share a port: tell them apart by address.
struct PacketFilter {
  std::optional<std::uint16_t> destination_port;
  std::optional<std::uint32_t> source_address;  // host byte order
  std::optional<std::uint16_t> info_port = std::nullopt;  // the sensor's second port (RoboSense DIFOP), if any
  [[nodiscard]] bool accepts(const UdpPacket& p) const {
    return (!destination_port || p.destination.port == *destination_port ||
            (info_port && p.destination.port == *info_port)) &&
           (!source_address || p.source.address == *source_address);
  }
};

struct SourceStats {
  std::uint64_t packets = 0;         // datagrams yielded
  std::uint64_t filtered = 0;        // datagrams that did not pass the filter
  std::uint64_t not_udp = 0;         // frames that were not IPv4/UDP (ARP, IPv6, TCP, ...)
  std::uint64_t malformed = 0;       // truncated or inconsistent frames, dropped
  std::uint64_t fragments_dropped = 0;  // IPv4 fragments never completed
  std::uint64_t kernel_drops = 0;    // live sockets: datagrams the kernel reports as dropped
  UdpEndpoint last_filtered{};       // live sockets: the source of the last datagram the filter dropped
};

class PacketSource {
 public:
  virtual ~PacketSource() = default;
  /// The next accepted datagram, or nullopt at end of input (pcap) / on timeout or stop (live).
  virtual std::optional<UdpPacket> next() = 0;
  [[nodiscard]] virtual const SourceStats& stats() const = 0;
  /// Non-empty when input ended abnormally (e.g. a pcap truncated mid-record): one line.
  [[nodiscard]] virtual std::string warning() const { return {}; }
};

}  // namespace rigcal::drivers
