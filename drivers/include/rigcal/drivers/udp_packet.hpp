#pragma once
// One UDP datagram as a decoder sees it, whether it came from a live socket or a pcap file.
#include <cstdint>
#include <span>
#include <string>

#include "rigcal/core/time.hpp"

namespace rigcal::drivers {

struct UdpEndpoint {
  std::uint32_t address = 0;  // IPv4, host byte order
  std::uint16_t port = 0;
  friend bool operator==(const UdpEndpoint&, const UdpEndpoint&) = default;
};

/// "a.b.c.d" ↔ host-order IPv4. parseIpv4 throws std::invalid_argument naming the text.
std::string formatIpv4(std::uint32_t address);
std::uint32_t parseIpv4(const std::string& text);

struct UdpPacket {
  std::span<const std::uint8_t> payload;  // valid until the source's next call
  TimeNs receive_ns = 0;                   // pcap record time, or kernel receive timestamp
  UdpEndpoint source;
  UdpEndpoint destination;
};

}  // namespace rigcal::drivers
