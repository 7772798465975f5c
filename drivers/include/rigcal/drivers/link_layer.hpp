#pragma once
// Parses one captured frame down to its IPv4 datagram: Ethernet (with 802.1Q/802.1ad VLAN tags),
// Linux cooked captures (SLL v1 and v2) and raw IPv4. Pure functions over bytes: safe on any input.
#include <cstdint>
#include <optional>
#include <span>

namespace rigcal::drivers {

/// libpcap link types we read (DLT_* values).
enum class LinkType : int { kEthernet = 1, kRaw = 101, kLinuxSll = 113, kLinuxSll2 = 276, kIpv4 = 228 };

struct Ipv4Header {
  std::uint32_t source = 0, destination = 0;  // host byte order
  std::uint16_t identification = 0;
  std::uint16_t fragment_offset = 0;  // bytes
  bool more_fragments = false;
  std::uint8_t protocol = 0;
  std::span<const std::uint8_t> payload;  // the IP payload (bounded by the header's total length)
};

enum class FrameResult { kIpv4, kNotIpv4, kMalformed };

/// Finds the IPv4 header of a frame of the given link type.
FrameResult parseFrame(LinkType link, std::span<const std::uint8_t> frame, Ipv4Header& out);

struct UdpHeader {
  std::uint16_t source_port = 0, destination_port = 0;
  std::span<const std::uint8_t> payload;
};

/// Parses a complete (reassembled) UDP datagram; nullopt when truncated or inconsistent.
std::optional<UdpHeader> parseUdp(std::span<const std::uint8_t> datagram);

}  // namespace rigcal::drivers
